//! Benchmarks, run in release builds: `speed` (methods × scenes), the paper's figures 8, 10
//! and 12 (`figures`), and seed 001's level-of-detail experiment (`lod`). This module holds
//! what they share: the configuration, the runner and the writers of CSV, PNG and report.

pub mod figures;
pub mod lod;
pub mod runner;
pub mod search;
pub mod speed;
pub mod startup;
pub mod trace_lod;

use std::path::PathBuf;

use clap::{Args, Subcommand};

use crate::args::ViewArgs;
use crate::scene::open_renderer;
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::gpu::Renderer;

use figures::{cases, plot_fig10, plot_fig12, plot_fig8, table};
pub use runner::{write_csv, write_png, FigureConfig, Runner};

/// The most timed frames per point a benchmark takes (a typo of a huge number would run forever).
pub const MAX_REPS: usize = 10_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Figure {
    Fig8,
    Fig10,
    Fig12,
    /// Seed 001's level-of-detail simulation (`bench_lod`).
    Lod,
    /// Seed 000's ray-tracing level-of-detail experiment (Table 2).
    TraceLod,
    All,
}

/// Runs the chosen figures and writes every output into `cfg.out`. Returns the report text.
pub fn run(runner: &Runner, which: Figure, adapter: &str) -> Result<String> {
    let cfg = &runner.cfg;
    std::fs::create_dir_all(&cfg.out).map_err(|e| Error::output(&cfg.out, format!("cannot create: {e}")))?;
    let want = |f: Figure| which == Figure::All || which == f;
    let (cases, skipped) =
        if want(Figure::Fig10) || want(Figure::Fig12) { cases(cfg)? } else { (Vec::new(), Vec::new()) };
    let steps = (if want(Figure::Fig8) { 3 * cfg.fig8_divisions().len() } else { 0 })
        + (if want(Figure::Fig10) { cases.len() * cfg.fig10_methods().len() } else { 0 })
        + (if want(Figure::Fig12) { cases.len() * (2 + cfg.slit_widths().len()) } else { 0 })
        + (if want(Figure::Lod) { runner.lod_steps() } else { 0 })
        + (if want(Figure::TraceLod) { runner.trace_lod_steps() } else { 0 });
    runner.progress.set_length(steps as u64);
    let mut report = if which == Figure::TraceLod {
        format!(
            "# twister: seed 000's ray-tracing experiment\n\nAdapter: {adapter}. Times: median of {} frames after a warm-up{}.\n\n",
            cfg.reps,
            if cfg.quick { " (quick run: lower resolution)" } else { "" },
        )
    } else {
        format!(
        "# twister: the paper's evaluations (seed 002 §4)\n\nAdapter: {adapter}. Image {}x{} per eye, both eyes, R_T = {} m, d_e = {} m, \
         paper vertical model. Times: median of {} frames after a warm-up, a scene's methods in turn{}. Errors: one more frame with the error pass.\n\n",
        cfg.projection.width,
        cfg.projection.height,
        cfg.projection.screen_radius,
        cfg.projection.eye_radius,
        cfg.reps,
        if cfg.quick { " (quick run: lower resolution, fewer points)" } else { "" },
        )
    };
    for line in &skipped {
        report += &format!("- **{line}**\n");
    }
    if crate::plot::font().is_none() {
        report += "- No TrueType font was found (set TWISTER_FONT): plots are drawn without text.\n";
    }
    report += "\n";
    let mut timing_note = None;
    if want(Figure::Fig8) {
        let (section, timing) = fig8_section(runner)?;
        report += &section;
        timing_note = timing_note.or(timing);
    }
    if want(Figure::Fig10) {
        let (section, timing) = fig10_section(runner, &cases)?;
        report += &section;
        timing_note = timing_note.or(timing);
    }
    if want(Figure::Fig12) {
        let (section, timing) = fig12_section(runner, &cases)?;
        report += &section;
        timing_note = timing_note.or(timing);
    }
    if want(Figure::Lod) {
        let (section, timing) = lod_section(runner)?;
        report += &section;
        timing_note = timing_note.or(timing);
    }
    if want(Figure::TraceLod) {
        let (points, chain, absent) = runner.trace_lod()?;
        timing_note = timing_note.or(points.first().map(|p| p.timing.clone()));
        report += &trace_lod::report(&cfg.out, &points, &chain, absent, &runner.trace_lod_projection())?;
    }
    if let Some(t) = timing_note {
        report += &format!(
            "Timing source: {}.\n",
            if t == "gpu-timestamps" {
                "GPU timestamp queries (start of the first pass to the end of the last)"
            } else {
                "wall time around submit-and-wait (no GPU timestamps: the adapter lacks them, or frames ran in several submissions; the `timing` column of the CSV says per point)"
            }
        );
    }
    twister::output::write_text(&cfg.out.join("report.md"), &report)?;
    Ok(report)
}

/// The report section of fig8, its outputs written to the output folder; and the
/// timing source of its points.
fn fig8_section(runner: &Runner) -> Result<(String, Option<String>)> {
    let cfg = &runner.cfg;
    let mut report = String::new();
    let points = runner.fig8()?;
    write_csv(&cfg.out.join("fig8.csv"), &points)?;
    twister::output::write_text(&cfg.out.join("fig8.json"), &serde_json::to_string_pretty(&points).unwrap())?;
    write_png(&cfg.out.join("fig8.png"), plot_fig8(&points))?;
    let at = |n: u32| {
        let v: Vec<String> = points.iter().filter(|p| p.parameter == n).map(|p| format!("{:.2}", p.mean_px)).collect();
        v.join(" / ")
    };
    report += &format!(
        "## Fig. 8: error vs division count\n\n![fig8](fig8.png)\n\nPaper: about 31 px mean at N = 1, under 1 px by N = 7, nearly the same at 1, 3 and 5 m. \
         Here (mean px at 1 / 3 / 5 m): N = 1: {}; N = 7: {}.\n\n{}\n",
        at(1),
        at(7),
        table(&points, false)
    );
    Ok((report, None))
}

/// The report section of fig10, its outputs written to the output folder; and the
/// timing source of its points.
fn fig10_section(runner: &Runner, cases: &[figures::Case]) -> Result<(String, Option<String>)> {
    let cfg = &runner.cfg;
    let mut report = String::new();
    let points = runner.fig10(cases)?;
    let timing_note = points.first().map(|p| p.timing.clone());
    write_csv(&cfg.out.join("fig10.csv"), &points)?;
    twister::output::write_text(&cfg.out.join("fig10.json"), &serde_json::to_string_pretty(&points).unwrap())?;
    write_png(&cfg.out.join("fig10.png"), plot_fig10(&points))?;
    let overhead: Vec<String> = cases
        .iter()
        .filter_map(|c| {
            let t = |m: &str| points.iter().find(|p| p.scene == c.label && p.method == m).map(|p| p.ms_frame);
            Some(format!(
                "{}: {:+.1} ms (adaptive:length), {:+.1} ms (adaptive, the error split)",
                c.label,
                t("adaptive:length")? - t("vertex")?,
                t("adaptive")? - t("vertex")?
            ))
        })
        .collect();
    report += &format!(
        "## Fig. 10: error and time per method\n\n![fig10](fig10.png)\n\nPaper: the proposed method's mean error under 1 px on every object; \
         its cost over drawing the vertices only (Prop − Vert): Sphere100 2 ms, Sphere1024 8 ms, Bunny 67 ms, Cube 30 ms; Bunny 14 fps \
         adaptive vs 134 fps undivided. Here (adaptive − vertex): {}.\n\n{}\n",
        overhead.join(", "),
        table(&points, true)
    );
    Ok((report, timing_note))
}

/// The report section of fig12, its outputs written to the output folder; and the
/// timing source of its points.
fn fig12_section(runner: &Runner, cases: &[figures::Case]) -> Result<(String, Option<String>)> {
    let cfg = &runner.cfg;
    let mut report = String::new();
    let (points, matched) = runner.fig12(cases)?;
    let timing_note = points.first().map(|p| p.timing.clone());
    write_csv(&cfg.out.join("fig12.csv"), &points)?;
    write_csv(&cfg.out.join("fig12_matched.csv"), &matched)?;
    let json = serde_json::json!({ "points": points, "matched": matched });
    twister::output::write_text(&cfg.out.join("fig12.json"), &serde_json::to_string_pretty(&json).unwrap())?;
    write_png(&cfg.out.join("fig12.png"), plot_fig12(&points))?;
    let mut m = String::from("| scene | method | ms | matched slit width w* | |\n|---|---|---|---|---|\n");
    for x in &matched {
        m += &format!(
            "| {} | {} | {:.1} | {} | {} |\n",
            x.scene,
            x.method,
            x.adaptive_ms,
            x.w_star.map_or("—".into(), |w| format!("{w:.1} px")),
            x.note
        );
    }
    report += &format!(
        "## Fig. 12: slit width vs adaptive\n\n![fig12](fig12.png)\n\nErrors here use the exact vertical model, the one slits converge to \
         (fig8 and fig10 use the paper's). Paper: w* ≈ 18 px (Sphere100), ≈ 10 px (Sphere1024), no advantage on its Bunny; slit:1 on \
         Sphere100 ran at 8.5 fps.\n\n{m}\n{}\n",
        table(&points, true)
    );
    Ok((report, timing_note))
}

/// The report section of lod, its outputs written to the output folder; and the
/// timing source of its points.
fn lod_section(runner: &Runner) -> Result<(String, Option<String>)> {
    let cfg = &runner.cfg;
    let mut report = String::new();
    let (points, absent) = runner.lod()?;
    let timing_note = points.first().map(|p| p.timing.clone());
    report += &crate::bench::lod::report(&cfg.out, &points, &absent)?;
    Ok((report, timing_note))
}

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Median frame time of each method on each scene, and its ratio to the first method.
    Speed(Box<SpeedArgs>),
    /// Seed 002 Fig. 8: error vs edge divisions on the evaluation triangles.
    Fig8(FigureArgs),
    /// Seed 002 Fig. 10: error, time and triangles per method on the evaluation scenes.
    Fig10(FigureArgs),
    /// Seed 002 Fig. 12: slit width vs adaptive, and the matched width.
    Fig12(FigureArgs),
    /// Seed 001: 12 bunnies, the gaze swept, with and without the visual-field level of detail.
    Lod(FigureArgs),
    /// Seed 000 Table 2: 8 cows, ray traced with and without the visual-field level of detail.
    TraceLod(FigureArgs),
    /// Every benchmark figure: fig8, fig10, fig12, lod and trace-lod.
    All(FigureArgs),
    /// Whole-process time of `twister render` commands in fresh processes: cold (Mesa's and
    /// twister's caches emptied), warm, and warm without twister's pipeline cache.
    Startup(StartupArgs),
    /// The random search for cracks, holes and lost geometry: random closed rooms and objects,
    /// viewers, panoramas, methods, sizes, eye models, heads and levels of detail, checked on the
    /// CPU twin and through the renderer; failures written as reproductions.
    Search(search::SearchArgs),
}

#[derive(Args)]
pub struct StartupArgs {
    /// A command to time (its arguments after `twister`, output into a scratch folder); may be
    /// repeated. Default: `render`, and `render builtin:triangle@3 --width 64 --height 16`.
    #[arg(long = "case", value_name = "ARGS")]
    pub cases: Vec<String>,
    /// Runs per case and cache state; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
    /// Also write the rows as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn bench_startup(args: &StartupArgs) -> Result<()> {
    if !(1..=100).contains(&args.reps) {
        return Err(Error::option("--reps", format!("must be between 1 and 100, got {}", args.reps)));
    }
    let cases: Vec<String> = if args.cases.is_empty() {
        startup::DEFAULT_CASES.iter().map(|c| c.to_string()).collect()
    } else {
        args.cases.clone()
    };
    if let Some(bad) = cases.iter().find(|c| c.split_whitespace().next() != Some("render")) {
        return Err(Error::option("--case", format!("times `render` commands only, got `{bad}`")));
    }
    let scratch = std::env::temp_dir().join(format!("twister-startup-{}", std::process::id()));
    let rows = startup::startup(&cases, args.reps, &scratch, |what| eprintln!("timing {what} ..."));
    let _ = std::fs::remove_dir_all(&scratch);
    let rows = rows?;
    println!("whole process, median of {} runs per case and cache state\n", args.reps);
    print!("{}", startup::startup_table(&rows));
    if let Some(path) = &args.json {
        let json = serde_json::json!({ "reps": args.reps, "rows": rows });
        twister::output::write_text(path, &serde_json::to_string_pretty(&json).unwrap())?;
    }
    Ok(())
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct FigureArgs {
    /// Output folder for the CSV, JSON, PNG plots and report.md.
    #[arg(long)]
    pub out: PathBuf,
    /// A smoke run: a quarter of the resolution, 2 reps, fewer points.
    #[arg(long)]
    pub quick: bool,
    /// Timed frames per point after a warm-up (default 5, quick 2).
    #[arg(long)]
    pub reps: Option<usize>,
    /// Folder of the third-party assets (bunny, Sponza); absent ones are skipped.
    #[arg(long, env = twister::core::assets::ASSETS_VAR, default_value = twister::core::assets::DEFAULT_ASSETS)]
    pub assets: PathBuf,
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct SpeedArgs {
    /// Scenes (.obj, .gltf or .glb files, or builtin:NAME).
    #[arg(required = true)]
    pub scenes: Vec<String>,
    /// Methods, comma-separated; ratios are against the first.
    #[arg(long, value_delimiter = ',', value_parser = Method::parse, default_value = "vertex,adaptive")]
    pub methods: Vec<Method>,
    /// Place file scenes DIST metres ahead, filling the screen height (built-in ones are placed already).
    #[arg(long, value_name = "DIST")]
    pub fit: Option<f32>,
    /// Timed frames per point (after one warm-up), the methods taking turns frame by frame; the
    /// median is reported.
    #[arg(long, default_value_t = 5)]
    pub reps: usize,
    /// Time each of the subdivision's passes apart (the balance table's ms, the JSON's
    /// `ms_subdivide_passes`), where the adapter has timestamps. Each pass boundary and its
    /// timestamps cost the software driver ~0.3–0.5 ms: compare frame times and ratios without it.
    #[arg(long)]
    pub pass_times: bool,
    #[command(flatten)]
    pub view: ViewArgs,
    /// Also write the rows as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn bench_figures(args: &FigureArgs, which: Figure) -> Result<()> {
    if let Some(reps) = args.reps.filter(|r| !(1..=MAX_REPS).contains(r)) {
        return Err(Error::option("--reps", format!("must be between 1 and {MAX_REPS}, got {reps}")));
    }
    let cfg = FigureConfig::new(args.quick, args.reps, args.assets.clone(), args.out.clone());
    let (renderer, adapter) = open_renderer()?;
    let progress = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap()
            .progress_chars("=> "),
    );
    let runner = Runner { renderer: &renderer, cfg, progress };
    let result = run(&runner, which, &adapter);
    runner.progress.finish_and_clear();
    result?;
    println!("{}", args.out.join("report.md").display());
    Ok(())
}

/// `bench speed`'s rows on an open renderer: each scene placed as `render` places it, each
/// method timed in turn; `progress` hears what is being timed.
pub fn speed_rows(renderer: &Renderer, args: &SpeedArgs, progress: impl FnMut(&str)) -> Result<Vec<speed::SpeedRow>> {
    let base = speed_settings(args)?;
    // Every scene as `render` would draw it: --scale, --fit (file scenes), --viewer camera:N, --lod.
    let mut scenes = Vec::new();
    for spec in &args.scenes {
        let fit = args.fit.filter(|_| !spec.starts_with("builtin:"));
        let prepared = crate::scene::prepare(renderer, spec, fit, &args.view, base, false, &args.methods)?;
        scenes.push(speed::SpeedScene {
            spec: spec.clone(),
            gpu_scene: prepared.gpu_scene,
            settings: prepared.settings.with_pass_times(args.pass_times),
        });
    }
    speed::speed(renderer, &scenes, &args.methods, args.reps, progress)
}

/// `bench speed`'s options checked: the base settings of every point.
fn speed_settings(args: &SpeedArgs) -> Result<twister::RenderSettings> {
    if !(1..=MAX_REPS).contains(&args.reps) {
        return Err(Error::option("--reps", format!("must be between 1 and {MAX_REPS}, got {}", args.reps)));
    }
    args.view.settings(&args.methods)
}

pub fn bench_speed(args: &SpeedArgs) -> Result<()> {
    // The options are checked before the device is opened.
    let base = speed_settings(args)?;
    let (renderer, adapter) = open_renderer()?;
    let rows = speed_rows(&renderer, args, |what| eprintln!("timing {what} ..."))?;
    let timing = rows.first().map_or("-".to_string(), |r| r.timing.clone());
    println!(
        "adapter: {adapter}; {}x{} per eye, both eyes; median of {} frames after a warm-up, the methods in turn; timing: {timing}\n",
        base.view.projection.width, base.view.projection.height, args.reps
    );
    print!("{}", speed::speed_table(&rows));
    println!("\nthe subdivision's balance:\n");
    print!("{}", speed::balance_table(&rows, args.pass_times));
    if let Some(path) = &args.json {
        let json = serde_json::json!({ "adapter": adapter, "width": base.view.projection.width, "height": base.view.projection.height, "rows": rows });
        twister::output::write_text(path, &serde_json::to_string_pretty(&json).unwrap())?;
    }
    Ok(())
}
