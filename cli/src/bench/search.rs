//! `twister bench search`: the random search for cracks, holes and lost geometry
//! (`twister::search`), for long runs: cases drawn from a seed, each checked on the CPU twin
//! (topology) and through the real renderer (background pixels, GPU = twin); every failure
//! shrunk and written as a reproduction (the scene as OBJ, the exact `twister render` command,
//! the case); a table of cases and failures per panorama and method at the end.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use twister::search::{self, CaseStream, Check, Failure, SearchCase, SearchMethod, SearchPanorama};
use twister::{Error, Renderer, Result};

use crate::scene::open_renderer;

/// Cases run and failures by check, per panorama and method family.
type Table = BTreeMap<(SearchPanorama, SearchMethod), (usize, BTreeMap<Check, usize>)>;

#[derive(Args)]
pub struct SearchArgs {
    /// Cases per panorama.
    #[arg(long, default_value_t = 100)]
    pub cases: usize,
    /// The seed the cases are drawn from (the same seed, the same cases).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Panoramas, comma-separated: cylinder, cylinder-head, equirect, vr180, fisheye, cubemap,
    /// cave [default: all].
    #[arg(long, value_delimiter = ',')]
    pub panoramas: Vec<String>,
    /// Methods, comma-separated: vertex, fixed, adaptive, adaptive:length [default: all].
    #[arg(long, value_delimiter = ',')]
    pub methods: Vec<String>,
    /// The largest image width drawn (pixels per eye).
    #[arg(long, default_value_t = 160)]
    pub max_width: u32,
    /// Only the CPU twin's topology (no device needed).
    #[arg(long)]
    pub cpu_only: bool,
    /// Tries at simplifying each failing case (each renders it again).
    #[arg(long, default_value_t = 32)]
    pub shrink_steps: usize,
    /// Where the failures' reproductions and the table go.
    #[arg(long, default_value = "search")]
    pub out: PathBuf,
}

fn parse_list<T>(
    option: &'static str,
    names: &[String],
    parse: impl Fn(&str) -> Option<T>,
    all: &str,
) -> Result<Vec<T>> {
    names
        .iter()
        .map(|n| parse(n.trim()).ok_or_else(|| Error::option(option, format!("unknown '{n}': expected one of {all}"))))
        .collect()
}

pub fn bench_search(args: &SearchArgs) -> Result<()> {
    if !(1..=1_000_000).contains(&args.cases) {
        return Err(Error::option("--cases", format!("must be between 1 and 1000000, got {}", args.cases)));
    }
    if args.shrink_steps > 10_000 {
        return Err(Error::option("--shrink-steps", format!("must be at most 10000, got {}", args.shrink_steps)));
    }
    if !(48..=2048).contains(&args.max_width) {
        return Err(Error::option("--max-width", format!("must be between 48 and 2048, got {}", args.max_width)));
    }
    let all_panoramas = SearchPanorama::ALL.map(|p| p.name()).join(", ");
    let all_methods = SearchMethod::ALL.map(|m| m.name()).join(", ");
    let mut panoramas = parse_list("--panoramas", &args.panoramas, SearchPanorama::parse, &all_panoramas)?;
    if panoramas.is_empty() {
        panoramas = SearchPanorama::ALL.to_vec();
    }
    let methods = parse_list("--methods", &args.methods, SearchMethod::parse, &all_methods)?;
    if let Some(p) = panoramas
        .iter()
        .find(|&&p| !SearchMethod::ALL.iter().any(|m| m.takes(p) && (methods.is_empty() || methods.contains(m))))
    {
        return Err(Error::option("--methods", format!("the {} takes none of these methods", p.name())));
    }
    std::fs::create_dir_all(&args.out).map_err(|e| Error::output(&args.out, e))?;
    let renderer = if args.cpu_only { None } else { Some(open_renderer()?.0) };
    let mut table: Table = BTreeMap::new();
    let mut failures = 0;
    let total = args.cases * panoramas.len();
    let progress = indicatif::ProgressBar::new(total as u64).with_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap()
            .progress_chars("=> "),
    );
    let started = std::time::Instant::now();
    for &panorama in &panoramas {
        // One stream per panorama: its cases do not depend on which other panoramas run.
        let mut stream = CaseStream::new(
            args.seed.wrapping_mul(0x9E37_79B9).wrapping_add(panorama as u64 * 1000),
            search::case_strategy(&[panorama], &methods, args.max_width),
        );
        for i in 0..args.cases {
            let tree = stream.next_tree();
            let case = tree.current();
            let row = table.entry((panorama, SearchMethod::of(case.method))).or_default();
            row.0 += 1;
            let case_started = std::time::Instant::now();
            let checked = search::check(renderer.as_ref(), &case);
            let seconds = case_started.elapsed().as_secs_f64();
            if seconds > SLOW_CASE_S {
                progress.suspend(|| {
                    eprintln!("case {i} of the {} took {seconds:.0} s ({})", panorama.name(), case.describe())
                });
            }
            if let Err(failure) = checked {
                *row.1.entry(failure.check).or_default() += 1;
                let say = |line: String| progress.suspend(|| eprintln!("{line}"));
                let at = Found { out: &args.out, panorama, index: i };
                failures += report_failure(renderer.as_ref(), tree, failure, args.shrink_steps, &at, failures, say)?;
            }
            progress.set_message(format!("{} failures", failures));
            progress.inc(1);
        }
    }
    progress.finish_and_clear();
    let report = table_text(&table, args, started.elapsed().as_secs_f64(), renderer.as_ref());
    print!("{report}");
    twister::output::write_text(&args.out.join("table.md"), &report)?;
    if failures > 0 {
        return Err(Error::option(
            "--cases",
            format!("{failures} of {total} cases failed: see {}", args.out.display()),
        ));
    }
    Ok(())
}

/// A case that takes longer than this is named on the way (a slow case is worth knowing: the
/// search is meant to run thousands in well under an hour).
const SLOW_CASE_S: f64 = 10.0;

/// Where a failing case was found: the output folder, its panorama and its index.
struct Found<'a> {
    out: &'a Path,
    panorama: SearchPanorama,
    index: usize,
}

/// A failing case said, shrunk (while the same check fails) and written; a panic met while
/// shrinking written apart. The failures written (numbered after `before`).
fn report_failure(
    renderer: Option<&Renderer>,
    tree: Box<dyn proptest::strategy::ValueTree<Value = SearchCase>>,
    failure: Failure,
    steps: usize,
    at: &Found,
    before: usize,
    say: impl Fn(String),
) -> Result<usize> {
    let case = tree.current();
    let (name, i) = (at.panorama.name(), at.index);
    say(format!(
        "case {i} of the {name}: {}: {} ({}); shrinking",
        failure.check.name(),
        failure.message,
        case.describe()
    ));
    let panicked = std::cell::RefCell::new(None);
    let small = search::shrink(tree, steps, |c| {
        let result = search::check(renderer, c);
        if let Err(f) = &result {
            if f.check == Check::Panic && failure.check != Check::Panic && panicked.borrow().is_none() {
                *panicked.borrow_mut() = Some((c.clone(), f.clone()));
            }
        }
        result.is_err_and(|f| f.check == failure.check)
    });
    let mut written = 0;
    if let Some((case, f)) = panicked.into_inner() {
        written += 1;
        let dir = at.out.join(format!("failure-{:03}-{name}-{i}-panic", before + written));
        write_reproduction(&dir, &case, &f)?;
        say(format!("{}: panic: {} ({})", dir.display(), f.message, case.describe()));
    }
    let failure = search::check(renderer, &small).err().unwrap_or(failure);
    written += 1;
    let dir = at.out.join(format!("failure-{:03}-{name}-{i}", before + written));
    write_reproduction(&dir, &small, &failure)?;
    say(format!("{}: {}: {} ({})", dir.display(), failure.check.name(), failure.message, small.describe()));
    Ok(written)
}

/// The table of cases and failures per panorama and method, with the command and the time.
fn table_text(table: &Table, args: &SearchArgs, seconds: f64, renderer: Option<&Renderer>) -> String {
    let mut s = String::new();
    let adapter = renderer.map_or("none (--cpu-only)".to_string(), |r| r.gpu.info.name.clone());
    let _ = writeln!(
        s,
        "twister bench search --cases {} --seed {} --max-width {}{}",
        args.cases,
        args.seed,
        args.max_width,
        if args.cpu_only { " --cpu-only" } else { "" }
    );
    let _ = writeln!(s, "adapter: {adapter}; {seconds:.0} s\n");
    let _ = writeln!(s, "| panorama | method | cases | topology | background | twin | settings | panic |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    let mut per_panorama: BTreeMap<SearchPanorama, (usize, usize)> = BTreeMap::new();
    for ((p, m), (cases, failed)) in table {
        let n = |c: Check| failed.get(&c).copied().unwrap_or(0);
        let _ = writeln!(
            s,
            "| {} | {} | {cases} | {} | {} | {} | {} | {} |",
            p.name(),
            m.name(),
            n(Check::Topology),
            n(Check::Background),
            n(Check::Twin),
            n(Check::Settings),
            n(Check::Panic)
        );
        let e = per_panorama.entry(*p).or_default();
        e.0 += cases;
        e.1 += failed.values().sum::<usize>();
    }
    let _ = writeln!(s, "\n| panorama | cases | failed |\n|---|---|---|");
    for (p, (cases, failed)) in per_panorama {
        let _ = writeln!(s, "| {} | {cases} | {failed} |", p.name());
    }
    s
}

/// A failure's folder: `scene.obj` (the room and its objects, one OBJ object each),
/// `cave.json` for the CAVE, `command.txt` (the `twister render` command that draws the case
/// on the marker background) and `case.txt` (the failure and every field of the case).
fn write_reproduction(dir: &Path, case: &SearchCase, failure: &Failure) -> Result<()> {
    let (scene, _, _, _) = search::drawn_scene(case);
    let mut obj = String::from("# a twister bench search case: the room, then its objects\n");
    for (o, object) in scene.objects.iter().enumerate() {
        let _ = writeln!(obj, "o {}", object.name.replace(' ', "_"));
        let range = 3 * object.first_triangle as usize..3 * (object.first_triangle + object.triangle_count) as usize;
        let used: Vec<u32> = {
            let mut u: Vec<u32> = scene.indices[range.clone()].to_vec();
            u.sort_unstable();
            u.dedup();
            u
        };
        for &i in &used {
            let [x, y, z] = scene.vertices[i as usize].position;
            let _ = writeln!(obj, "v {x:?} {y:?} {z:?}");
        }
        let first_v = obj_vertex_count_before(&scene, o);
        for t in scene.indices[range].chunks(3) {
            let idx = |i: u32| first_v + used.binary_search(&i).unwrap() + 1;
            let _ = writeln!(obj, "f {} {} {}", idx(t[0]), idx(t[1]), idx(t[2]));
        }
    }
    let mut files = vec![(dir.join("scene.obj"), obj)];
    let mut command = format!("twister render scene.obj {}", render_options(case));
    if case.panorama == SearchPanorama::Cave {
        let walls: Vec<serde_json::Value> = case
            .cave_walls()
            .iter()
            .map(|w| {
                serde_json::json!({"name": w.name, "lower_left": w.lower_left, "lower_right": w.lower_right,
                    "upper_left": w.upper_left, "pixels": w.pixels})
            })
            .collect();
        files.push((
            dir.join("cave.json"),
            serde_json::to_string_pretty(&serde_json::json!({ "walls": walls })).unwrap(),
        ));
        command += " --cave cave.json";
    }
    files.push((dir.join("command.txt"), command + "\n"));
    files.push((
        dir.join("case.txt"),
        format!("{}: {}\n{}\n\n{:#?}\n", failure.check.name(), failure.message, case.describe(), case),
    ));
    for (path, text) in files {
        twister::output::write_text(&path, &text)?;
    }
    Ok(())
}

/// The number of OBJ vertices written for the objects before `o` (each writes the vertices
/// its triangles use).
fn obj_vertex_count_before(scene: &twister::Scene, o: usize) -> usize {
    scene.objects[..o]
        .iter()
        .map(|object| {
            let range =
                3 * object.first_triangle as usize..3 * (object.first_triangle + object.triangle_count) as usize;
            let mut u: Vec<u32> = scene.indices[range].to_vec();
            u.sort_unstable();
            u.dedup();
            u.len()
        })
        .sum()
}

/// The `twister render` options that draw a case as the search drew it.
pub fn render_options(case: &SearchCase) -> String {
    let list = |v: [f32; 3]| format!("{:?},{:?},{:?}", v[0], v[1], v[2]);
    let mut o = format!(
        "--panorama {} --method {} --width {} --edge-px {:?} --max-error-px {:?} --max-div {} --viewer {} --yaw {:?} \
         --screen-radius {:?} --eye-radius {:?} --samples 1 --anisotropy 1 --background 255,0,255 --layout eyes --out out",
        case.panorama.kind().name(),
        case.method.name(),
        case.settings().projection().width,
        case.edge_px,
        case.max_error_px,
        case.max_div,
        list(case.viewer),
        case.yaw_deg,
        case.screen_radius,
        case.eye_radius,
    );
    let p = case.projection();
    match case.panorama {
        SearchPanorama::Cylinder | SearchPanorama::CylinderHead => {
            let _ = write!(
                o,
                " --height {} --vertical {}",
                p.height,
                if case.vertical == twister::Vertical::Exact { "exact" } else { "paper" }
            );
        }
        SearchPanorama::Fisheye => {
            let _ = write!(o, " --fov {:?} --dome-tilt {:?}", case.fov, case.dome_tilt);
        }
        _ => {}
    }
    if case.panorama.kind().is_sphere() {
        let _ = write!(o, " --convergence {}", case.convergence.map_or("parallel".to_string(), |c| format!("{c:?}")));
        let _ = write!(o, " --pole-merge {}", if case.pole_merge { "60,75" } else { "off" });
    }
    if let Some((offset, yaw)) = case.head {
        let at = [0, 1, 2].map(|i| case.viewer[i] + offset[i]);
        let _ = write!(o, " --head {},{yaw:?}", list(at));
    }
    if let Some((yaw, pitch)) = case.gaze {
        let _ = write!(o, " --lod visual-field --gaze {yaw:?},{pitch:?}");
    }
    o
}
