//! The `twister` command-line tool.

mod bench;
mod heatmap;
mod plot;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use glam::Vec3;

use bench::{Figure, FigureConfig, Runner};
use twister::core::load::load_scene;
use twister::core::lod::{LodChain, LodParams, LodSelection};
use twister::core::settings::{Method, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, DEFAULT_MEMORY_MB};
use twister::core::visual_field::{Field, Gaze};
use twister::error::{Error, Result};
use twister::gpu::Gpu;
use twister::output::{layout_images, write_images, write_text, Layout};
use twister::{EyeImage, GpuScene, Projection, RenderSettings, Renderer, Scene, Vertical};

#[derive(Parser)]
#[command(name = "twister", version, about = "Omnidirectional stereo (TWISTER concentric-mosaic) rendering on the GPU")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene into the left- and right-eye panoramas.
    Render(RenderArgs),
    /// Measure the display-position error of a method (seed 002 §4.1).
    Error(ErrorArgs),
    /// Describe a scene file as JSON: triangles, objects, materials, bounds, cameras, warnings,
    /// and a suggested viewer position.
    Info(InfoArgs),
    /// Benchmarks (release builds): `speed` times methods on scenes.
    #[command(subcommand)]
    Bench(BenchCommand),
}

#[derive(Args)]
struct InfoArgs {
    /// Scene: a .obj, .gltf or .glb file, or a built-in scene.
    scene: String,
}

#[derive(Args)]
struct ErrorArgs {
    /// Scene: a .obj, .gltf or .glb file, or builtin:demo, builtin:sphere100, builtin:sphere1024, builtin:triangle@D.
    #[arg(default_value = "builtin:demo")]
    scene: String,
    /// Move and scale the scene so that it stands DIST metres ahead, filling the screen height.
    #[arg(long, value_name = "DIST")]
    fit: Option<f32>,
    #[command(flatten)]
    view: ViewArgs,
    /// Print one JSON object instead of a summary.
    #[arg(long)]
    json: bool,
    /// Write the per-pixel error, colour-mapped with its scale, to this PNG (left eye on top).
    #[arg(long, value_name = "FILE.png")]
    heatmap: Option<PathBuf>,
    /// Top of the heatmap's scale in pixels (default: a round value at or above the p99 error).
    #[arg(long, value_name = "PX")]
    heatmap_max: Option<f32>,
    /// Also render with this method and report how much of the image shows a different surface,
    /// and the colour PSNR (e.g. --against slit:1).
    #[arg(long, value_parser = Method::parse, value_name = "METHOD")]
    against: Option<Method>,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Median frame time of each method on each scene, and its ratio to the first method.
    Speed(SpeedArgs),
    /// Seed 002 Fig. 8: error vs edge divisions on the evaluation triangles.
    Fig8(FigureArgs),
    /// Seed 002 Fig. 10: error, time and triangles per method on the evaluation scenes.
    Fig10(FigureArgs),
    /// Seed 002 Fig. 12: slit width vs adaptive, and the matched width.
    Fig12(FigureArgs),
    /// Seed 001: 12 bunnies, the gaze swept, with and without the visual-field level of detail.
    Lod(FigureArgs),
    /// All three figures.
    All(FigureArgs),
}

#[derive(Args)]
struct FigureArgs {
    /// Output folder for the CSV, JSON, PNG plots and report.md.
    #[arg(long)]
    out: PathBuf,
    /// A smoke run: a quarter of the resolution, 2 reps, fewer points.
    #[arg(long)]
    quick: bool,
    /// Timed frames per point after a warm-up (default 5, quick 2).
    #[arg(long)]
    reps: Option<usize>,
    /// Folder of the third-party assets (bunny, Sponza); absent ones are skipped.
    #[arg(long, default_value = "../shared/assets")]
    assets: PathBuf,
}

#[derive(Args)]
struct SpeedArgs {
    /// Scenes (.obj, .gltf or .glb files, or builtin:NAME).
    #[arg(required = true)]
    scenes: Vec<String>,
    /// Methods, comma-separated; ratios are against the first.
    #[arg(long, value_delimiter = ',', value_parser = Method::parse, default_value = "vertex,adaptive")]
    methods: Vec<Method>,
    /// Place file scenes DIST metres ahead, filling the screen height (built-in ones are placed already).
    #[arg(long, value_name = "DIST")]
    fit: Option<f32>,
    /// Timed frames per point (after one warm-up); the median is reported.
    #[arg(long, default_value_t = 5)]
    reps: usize,
    #[command(flatten)]
    view: ViewArgs,
    /// Also write the rows as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Args)]
struct ViewArgs {
    /// Image width per eye in pixels (the full 360°).
    #[arg(long, default_value_t = 3168)]
    width: u32,
    /// Image height per eye in pixels.
    #[arg(long, default_value_t = 600)]
    height: u32,
    /// R_T: radius of the display cylinder, metres.
    #[arg(long, default_value_t = 1.0)]
    screen_radius: f32,
    /// d_e: radius of the circle the eyes move on, metres.
    #[arg(long, default_value_t = 0.032)]
    eye_radius: f32,
    /// Vertical model: paper (v = R_T·y/r) or exact (pinhole on the eye circle).
    #[arg(long, value_enum, default_value_t = Vertical::Paper)]
    vertical: Vertical,
    /// Viewer: a position x,y,z in scene units, or camera[:N] for the file's N-th camera (default 0;
    /// its position and yaw, plus --yaw).
    #[arg(long, value_parser = parse_viewer, default_value = "0,0,0", allow_hyphen_values = true)]
    viewer: Viewer,
    /// Turn of the view about the vertical axis, degrees; positive turns left.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw: f32,
    /// Metres per scene unit: the scene (and --viewer, given in scene units) is scaled by it.
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
    /// Subdivision: adaptive (N = ceil(l/L) per edge), fixed:N (every edge N), vertex (none).
    #[arg(long, value_parser = Method::parse, default_value = "adaptive")]
    method: Method,
    /// L: the longest projected edge `adaptive` leaves, pixels.
    #[arg(long, default_value_t = DEFAULT_EDGE_PX)]
    edge_px: f32,
    /// N_max: the largest lattice step of one piece; larger polygons are pre-split.
    #[arg(long, default_value_t = DEFAULT_MAX_DIV)]
    max_div: u32,
    /// Memory budget of the subdivision buffers, MiB; scenes that need more run in chunks.
    #[arg(long, default_value_t = DEFAULT_MEMORY_MB)]
    memory_mb: u32,
    /// Level of detail: off, or visual-field (seeds 001/000: polygon budgets and subdivision by
    /// where each object falls in the visual field of --gaze).
    #[arg(long, value_enum, default_value_t = LodMode::Off)]
    lod: LodMode,
    /// Gaze direction YAW,PITCH in degrees from straight ahead (yaw positive left, pitch up).
    #[arg(long, value_parser = parse_gaze, default_value = "0,0", allow_hyphen_values = true)]
    gaze: Gaze,
    /// P2'/P1: the peripheral field's smallest share of an object's triangles.
    #[arg(long, default_value_t = 0.3)]
    lod_p2: f32,
    /// P3/P1: the share of an object's triangles outside the visual field.
    #[arg(long, default_value_t = 0.05)]
    lod_p3: f32,
    /// D∞, metres: the budgets fall linearly with distance to 0 at D∞ (eq. 2).
    #[arg(long, default_value_t = 100.0)]
    lod_dinf: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum LodMode {
    Off,
    VisualField,
}

fn parse_gaze(s: &str) -> std::result::Result<Gaze, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [yaw, pitch] if yaw.is_finite() && pitch.is_finite() && pitch.abs() <= 89.0 => Ok(Gaze::new(yaw, pitch)),
        _ => Err(format!("'{s}': expected YAW,PITCH in degrees, pitch within ±89")),
    }
}

#[derive(Args)]
struct RenderArgs {
    /// Scene to render: a .obj, .gltf or .glb file, or builtin:demo, builtin:sphere100, builtin:sphere1024, builtin:triangle@D.
    #[arg(default_value = "builtin:demo")]
    scene: String,
    /// Move and scale the scene so that it stands DIST metres ahead, filling the screen height.
    #[arg(long, value_name = "DIST")]
    fit: Option<f32>,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    view: ViewArgs,
    /// Output layout: eyes (left.png, right.png), top-bottom (stereo.png), twister (four W/2×H images).
    #[arg(long, value_enum, default_value_t = Layout::Eyes)]
    layout: Layout,
    /// Background colour R,G,B, each 0–255.
    #[arg(long, value_parser = parse_rgb, default_value = "26,26,31")]
    background: [f32; 3],
    /// Write render statistics as JSON to this file.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// With --lod visual-field: tint each object by its level and draw the central-field
    /// (white) and visual-field (orange) boundaries.
    #[arg(long)]
    lod_overlay: bool,
}

#[derive(Clone, Copy, Debug)]
enum Viewer {
    At(Vec3),
    Camera(usize),
}

fn parse_viewer(s: &str) -> std::result::Result<Viewer, String> {
    match s.strip_prefix("camera") {
        Some("") => Ok(Viewer::Camera(0)),
        Some(rest) => rest
            .strip_prefix(':')
            .and_then(|n| n.parse().ok())
            .map(Viewer::Camera)
            .ok_or_else(|| format!("'{s}': expected camera or camera:N")),
        None => parse_vec3(s).map(Viewer::At),
    }
}

fn parse_vec3(s: &str) -> std::result::Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("'{s}': expected three finite numbers x,y,z")),
    }
}

fn parse_rgb(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<u32> =
        s.split(',').map(|x| x.trim().parse::<u32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [r, g, b] if r <= 255 && g <= 255 && b <= 255 => Ok([r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0]),
        _ => Err(format!("'{s}': expected R,G,B with each channel 0–255")),
    }
}

impl ViewArgs {
    fn settings(&self) -> Result<RenderSettings> {
        let projection = Projection {
            screen_radius: self.screen_radius,
            eye_radius: self.eye_radius,
            width: self.width,
            height: self.height,
            vertical: self.vertical,
        };
        projection.validate()?;
        if !self.yaw.is_finite() {
            return Err(Error::option("--yaw", "must be a finite number of degrees"));
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(Error::option("--scale", format!("must be a positive number of metres per scene unit, got {}", self.scale)));
        }
        let settings = RenderSettings::new(projection).with_viewer(match self.viewer {
                Viewer::At(p) => p * self.scale,
                Viewer::Camera(_) => Vec3::ZERO, // placed by `setup` once the scene is loaded
            }).with_yaw_deg(self.yaw).with_method(self.method).with_edge_px(self.edge_px).with_max_div(self.max_div).with_memory_mb(self.memory_mb);
        settings.validate()?;
        Ok(settings)
    }
}

/// Loads (and places) a scene, opens the GPU and uploads the scene.
/// Loads (and places) a scene; a `camera[:N]` viewer takes that camera's place and yaw.
fn place(spec: &str, fit: Option<f32>, view: &ViewArgs, settings: &mut RenderSettings) -> Result<Scene> {
    let mut scene = load_scene(spec, &settings.view.projection)?;
    if view.scale != 1.0 {
        scene.transform(glam::Mat4::from_scale(Vec3::splat(view.scale)));
    }
    if let Some(d) = fit {
        scene.fit(d, &settings.view.projection)?;
    }
    if let Viewer::Camera(n) = view.viewer {
        let cam = scene
            .cameras
            .get(n)
            .ok_or_else(|| Error::scene(spec, format!("--viewer camera:{n}, but the file has {} cameras", scene.cameras.len())))?;
        settings.view.viewer = Vec3::from(cam.position) * view.scale;
        settings.view.yaw_deg += cam.yaw_deg;
    }
    Ok(scene)
}

/// Loads and places the scene, opens the GPU and uploads it; with `--lod visual-field`, draws
/// the gaze's selection (tinted by level for the overlay).
fn setup(
    spec: &str,
    fit: Option<f32>,
    view: &ViewArgs,
    settings: &mut RenderSettings,
    overlay: bool,
) -> Result<(Renderer, GpuScene, String, Option<LodSelection>)> {
    let mut scene = place(spec, fit, view, settings)?;
    let selection = match view.lod {
        LodMode::Off => None,
        LodMode::VisualField => {
            let params = LodParams { p2: view.lod_p2, p3: view.lod_p3, d_inf: view.lod_dinf };
            params.validate()?;
            let chain = LodChain::build(&scene, params.p3);
            Some(chain.select(&scene, settings.view(), &view.gaze, &params))
        }
    };
    if let (Some(sel), true) = (&selection, overlay) {
        twister::core::lod::tint(&mut scene, sel);
    }
    let gpu = Gpu::new()?;
    let adapter = gpu.adapter_description();
    let renderer = Renderer::new(gpu)?;
    let mut gpu_scene = GpuScene::upload(&renderer.gpu, &scene)?;
    if let Some(sel) = &selection {
        gpu_scene = gpu_scene.with_lod(&renderer.gpu, sel);
    }
    Ok((renderer, gpu_scene, adapter, selection))
}

/// The LOD part of the stats: triangles selected and, per field, objects and triangles.
fn lod_stats(selection: &Option<LodSelection>) -> serde_json::Value {
    let Some(sel) = selection else { return serde_json::Value::Null };
    let per = |f: Field| {
        let c: Vec<_> = sel.chosen.iter().filter(|c| c.field == f).collect();
        serde_json::json!({ "objects": c.len(), "triangles": c.iter().map(|c| c.triangles as u64).sum::<u64>() })
    };
    serde_json::json!({
        "triangles_selected": sel.triangle_count(),
        "central": per(Field::Central),
        "peripheral": per(Field::Peripheral),
        "outside": per(Field::Outside),
    })
}

fn info(args: &InfoArgs) -> Result<()> {
    let scene = load_scene(&args.scene, &Projection::default())?;
    let (lo, hi) = scene.bounds().ok_or_else(|| Error::scene(&args.scene, "no triangles"))?;
    let suggestion = twister::core::load::suggested_viewer(&scene);
    let json = serde_json::json!({
        "scene": args.scene,
        "triangles": scene.triangle_count(),
        "vertices": scene.vertices.len(),
        "objects": scene.objects.len(),
        "meshes": scene.meshes,
        "primitives": scene.primitives,
        "materials": scene.materials.len(),
        "textures": scene.textures.iter().map(|t| serde_json::json!({ "name": t.name, "width": t.width, "height": t.height })).collect::<Vec<_>>(),
        "bbox": { "min": lo.to_array(), "max": hi.to_array() },
        "cameras": scene.cameras,
        "warnings": scene.warnings,
        "suggested_viewer": suggestion.map(|(p, where_)| serde_json::json!({ "position": p, "where": where_ })),
    });
    println!("{}", serde_json::to_string_pretty(&json).unwrap());
    Ok(())
}

fn render(args: &RenderArgs) -> Result<()> {
    let mut settings = args.view.settings()?;
    settings.shading.background = args.background;
    settings.measure.edges = args.stats.is_some();
    if args.lod_overlay && args.view.lod == LodMode::Off {
        return Err(Error::option("--lod-overlay", "needs --lod visual-field"));
    }
    let (renderer, gpu_scene, adapter, selection) =
        setup(&args.scene, args.fit, &args.view, &mut settings, args.lod_overlay)?;
    let mut frame = renderer.render(&gpu_scene, &settings)?;
    if args.lod_overlay {
        for img in [&mut frame.left, &mut frame.right] {
            twister::core::lod::draw_field_boundaries(img, &settings.view.projection, &args.view.gaze);
        }
    }
    let t = std::time::Instant::now();
    let written = write_images(&args.out, &layout_images(&frame, args.layout))?;
    let ms_write = t.elapsed().as_secs_f64() * 1e3;
    for p in &written {
        println!("{}", p.display());
    }
    if let Some(path) = &args.stats {
        let s = &frame.stats;
        let json = serde_json::json!({
            "scene": args.scene,
            "method": settings.subdivision.method.name(),
            "edge_px": settings.subdivision.edge_px,
            "max_div": settings.subdivision.max_div,
            "triangles_in": s.triangles_in,
            "triangles_out": s.triangles_out,
            "triangles_drawn": s.triangles_out,
            "pieces": s.pieces,
            "max_sub_edge_px": s.max_sub_edge_px,
            "chunks": s.chunks,
            "width": settings.view.projection.width,
            "height": settings.view.projection.height,
            "screen_radius": settings.view.projection.screen_radius,
            "eye_radius": settings.view.projection.eye_radius,
            "vertical": settings.view.projection.vertical,
            "layout": args.layout,
            "adapter": adapter,
            "ms_subdivide": s.ms_subdivide,
            "ms_prepare": s.ms_subdivide,
            "ms_raster": s.ms_raster,
            "ms_readback": s.ms_readback,
            "ms_write": ms_write,
            "ms_total": s.ms_total + ms_write,
            "lod": lod_stats(&selection),
        });
        write_text(path, &serde_json::to_string_pretty(&json).unwrap())?;
    }
    Ok(())
}

fn error(args: &ErrorArgs) -> Result<()> {
    let mut settings = args.view.settings()?.with_measure_error(true);
    let (renderer, gpu_scene, adapter, selection) = setup(&args.scene, args.fit, &args.view, &mut settings, false)?;
    let frame = renderer.render(&gpu_scene, &settings)?;
    let measured = frame.measurement.as_ref().expect("rendered with measure_error");
    let e = &measured.stats;
    let s = &frame.stats;
    let mut json = serde_json::json!({
        "scene": args.scene,
        "method": settings.subdivision.method.name(),
        "vertical": settings.view.projection.vertical,
        "width": settings.view.projection.width,
        "height": settings.view.projection.height,
        "mean_px": e.mean,
        "std_px": e.std_dev,
        "p50_px": e.p50,
        "p90_px": e.p90,
        "p99_px": e.p99,
        "max_px": e.max,
        "pixels": e.count,
        "lod": lod_stats(&selection),
        "triangles_in": s.triangles_in,
        "triangles_out": s.triangles_out,
        "ms_render": s.ms_frame,
        "timing": s.timing,
        "ms_total": s.ms_total,
        "adapter": adapter,
    });
    if let Some(method) = args.against {
        let reference = renderer.render(&gpu_scene, &settings.clone().with_method(method))?;
        let c = twister::core::compare::compare(&frame, &reference)?;
        json["against"] = serde_json::json!(method.name());
        json["different_surface_fraction"] = serde_json::json!(c.different_surface_fraction);
        json["psnr_db"] = serde_json::json!(c.psnr_db);
    }
    if let Some(path) = &args.heatmap {
        let max = args.heatmap_max.unwrap_or_else(|| crate::heatmap::nice_max(e.p99));
        let (w, h, rgba) =
            crate::heatmap::heatmap(&measured.error, settings.view.projection.width, settings.view.projection.height, max);
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "heatmap.png".into());
        let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
        write_images(dir, &[(name, EyeImage { width: w, height: h, rgba })])?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&json).unwrap());
    } else {
        println!(
            "{} {} ({}): mean {:.3} px, std {:.3}, p50 {:.3}, p90 {:.3}, p99 {:.3}, max {:.3} over {} pixels; {} triangles drawn; {:.1} ms",
            args.scene,
            settings.subdivision.method.name(),
            json["vertical"].as_str().unwrap_or(""),
            e.mean,
            e.std_dev,
            e.p50,
            e.p90,
            e.p99,
            e.max,
            e.count,
            s.triangles_out,
            s.ms_frame
        );
        if let Some(f) = json.get("different_surface_fraction") {
            println!(
                "against {}: different surface on {:.4} of pixels, PSNR {} dB",
                json["against"], f, json["psnr_db"]
            );
        }
    }
    Ok(())
}

fn bench_figures(args: &FigureArgs, which: Figure) -> Result<()> {
    let cfg = FigureConfig::new(args.quick, args.reps, args.assets.clone(), args.out.clone());
    let gpu = Gpu::new()?;
    let adapter = gpu.adapter_description();
    let renderer = Renderer::new(gpu)?;
    let progress = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap()
            .progress_chars("=> "),
    );
    let runner = Runner { renderer: &renderer, cfg, progress };
    let result = bench::run(&runner, which, &adapter);
    runner.progress.finish_and_clear();
    result?;
    println!("{}", args.out.join("report.md").display());
    Ok(())
}

fn bench_speed(args: &SpeedArgs) -> Result<()> {
    if args.reps == 0 {
        return Err(Error::option("--reps", "must be at least 1"));
    }
    let settings = args.view.settings()?;
    let gpu = Gpu::new()?;
    let adapter = gpu.adapter_description();
    let renderer = Renderer::new(gpu)?;
    let rows = crate::bench::speed::speed(&renderer, &args.scenes, args.fit, &args.methods, &settings, args.reps, |what| {
        eprintln!("timing {what} ...")
    })?;
    println!(
        "adapter: {adapter}; {}x{} per eye, both eyes; median of {} frames after a warm-up; wall time around submit-and-wait\n",
        settings.view.projection.width, settings.view.projection.height, args.reps
    );
    print!("{}", crate::bench::speed::speed_table(&rows));
    if let Some(path) = &args.json {
        let json = serde_json::json!({ "adapter": adapter, "width": settings.view.projection.width, "height": settings.view.projection.height, "rows": rows });
        write_text(path, &serde_json::to_string_pretty(&json).unwrap())?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(args) => render(args),
        Command::Error(args) => error(args),
        Command::Info(args) => info(args),
        Command::Bench(BenchCommand::Speed(args)) => bench_speed(args),
        Command::Bench(BenchCommand::Fig8(args)) => bench_figures(args, Figure::Fig8),
        Command::Bench(BenchCommand::Fig10(args)) => bench_figures(args, Figure::Fig10),
        Command::Bench(BenchCommand::Fig12(args)) => bench_figures(args, Figure::Fig12),
        Command::Bench(BenchCommand::Lod(args)) => bench_figures(args, Figure::Lod),
        Command::Bench(BenchCommand::All(args)) => bench_figures(args, Figure::All),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
