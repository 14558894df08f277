//! `twister bench trace-lod`: seed 000's experiment (§4, Table 2) on this ray tracer. Eight cows
//! (`cow/cow.obj`, 5,804 triangles: N_max; N_min = 500), one point light above the viewer,
//! Reflect_max = 3, in four scenes: A mirror cows all around, B diffuse cows all around, C mirror
//! cows ahead only, D diffuse cows ahead only. Each is traced plainly and with the visual-field
//! level of detail for two gazes: state 1 straight ahead, state 2 down (the seed's floor screen);
//! with LOD both with eq. 10 (each cow's chain down to 500 triangles, the level per ray) and
//! without it (eq. 8–9 only: untraced outside the field, fewer bounces), so that what the polygon
//! control adds shows apart.
//!
//! Choices where the seed is silent or its display differs: the panorama is the full-sphere ODS
//! (640×320 per eye, both eyes: 409,600 rays, about the seed's 256×256×6). The seed's CAVE had a
//! front, a right and a floor screen, and "all around" put cows evenly on all three: here four
//! cows stand around the viewer at eye level (every 90°, 2.5 m away) and four below it (45° down,
//! between them), as on a floor screen; "ahead only" puts all eight within ±35° of straight ahead
//! (two rows, at eye level 3 m away and 20° down 3.5 m away). The cows are 1.5 m tall, nothing else is in the scene
//! (no floor: the seed names none), the light 2.5 m above the eyes; state 2 gazes 60° down.

use std::path::Path;

use glam::{Mat4, Vec3};
use serde::Serialize;

use crate::bench::runner::{write_csv, write_png, Runner};
use crate::bench::speed::median;
use crate::plot::{draw_panels, Chart, Series, PALETTE};
use twister::core::detail::lod::LodChain;
use twister::core::detail::visual_field::Gaze;
use twister::core::scenes::bvh::SceneBvh;
use twister::core::scenes::load::load_obj;
use twister::core::scenes::scene::Scene;
use twister::core::settings::Method;
use twister::core::shading::material::Material;
use twister::error::{Error, Result};
use twister::{Frame, GpuScene, Projection, RenderSettings};

/// Seed 000's polygon counts: N_max (the cow) and N_min.
pub const COW_TRIANGLES: u32 = 5804;
pub const MIN_TRIANGLES: u32 = 500;

/// A row of the seed's Table 2, seconds per frame: (scene, proposed state 1, proposed state 2, plain).
pub type SeedRow = (&'static str, f64, f64, f64);

/// The seed's Table 2.
pub const SEED_TABLE_2: [SeedRow; 4] =
    [("A", 2.078, 0.751, 1.641), ("B", 1.109, 0.547, 0.969), ("C", 0.859, 0.243, 0.875), ("D", 0.484, 0.203, 0.532)];

/// The gazes: state 1 ahead, state 2 down at the floor.
pub const STATES: [(&str, f32, f32); 2] = [("state 1", 0.0, 0.0), ("state 2", 0.0, -60.0)];

/// How a frame is traced.
pub const CONFIGS: [&str; 3] = ["plain", "lod", "lod without eq. 10"];

/// What `bench trace-lod` measured: the points; the first cow's chain (triangles and error bound
/// per level); the line to report if the cow is absent (then nothing ran).
pub type TraceLodResults = (Vec<TraceLodPoint>, Vec<(u32, f32)>, Option<String>);

/// One scene, state and configuration.
#[derive(Clone, Debug, Serialize)]
pub struct TraceLodPoint {
    pub scene: String,
    /// "state 1", "state 2", or "-" (plain tracing does not depend on the gaze).
    pub state: String,
    pub config: String,
    pub s_frame: f64,
    pub rays_traced: u64,
    pub triangle_tests: u64,
    /// Pixels (both eyes) that show a surface.
    pub covered_pixels: u64,
    pub timing: String,
}

/// The light's height above the eyes and the cows' height, metres.
const LIGHT_HEIGHT: f32 = 2.5;
const COW_HEIGHT: f32 = 1.5;

/// One of the four scenes: eight cows, mirrors or diffuse, around or ahead.
pub fn scene(cow: &Scene, mirror: bool, around: bool) -> Result<Scene> {
    let (lo, hi) = cow.bounds().ok_or_else(|| Error::scene("cow", "the model has no triangles"))?;
    let s = COW_HEIGHT / (hi.y - lo.y);
    let centre = (lo + hi) / 2.0;
    let mut out = Scene::new(format!(
        "{} cows {}",
        if mirror { "mirror" } else { "diffuse" },
        if around { "around" } else { "ahead" }
    ));
    // Vertex material 1 is `materials[0]` (0: the default material).
    out.materials = vec![Material { mirror: if mirror { 0.85 } else { 0.0 }, ..Material::default() }];
    // (azimuth left of ahead, elevation, distance) of each cow's centre.
    let places: Vec<(f32, f32, f32)> = if around {
        (0..4)
            .map(|k| (90.0 * k as f32, 0.0, 2.5))
            .chain((0..4).map(|k| (45.0 + 90.0 * k as f32, -45.0, 2.5)))
            .collect()
    } else {
        (0..4)
            .map(|k| (-30.0 + 20.0 * k as f32, 0.0, 3.0))
            .chain((0..4).map(|k| (-20.0 + 20.0 * k as f32, -20.0, 3.5)))
            .collect()
    };
    let colour = if mirror { [0.92, 0.92, 0.95, 1.0] } else { [0.75, 0.58, 0.42, 1.0] };
    for (k, (azimuth, elevation, distance)) in places.into_iter().enumerate() {
        let (a, e) = (azimuth.to_radians(), elevation.to_radians());
        let at = distance * Vec3::new(-a.sin() * e.cos(), e.sin(), -a.cos() * e.cos());
        // Side-on to the viewer, upright.
        let m = Mat4::from_translation(at)
            * Mat4::from_rotation_y(a)
            * Mat4::from_scale(Vec3::splat(s))
            * Mat4::from_translation(-centre);
        let mut one = cow.clone();
        one.transform(m);
        for v in &mut one.vertices {
            v.material = 1;
            v.color = colour;
        }
        out.add_mesh(format!("cow {k}"), &one.vertices, &one.indices);
    }
    Ok(out)
}

impl Runner<'_> {
    pub fn trace_lod_projection(&self) -> Projection {
        Projection::equirect(if self.cfg.quick { 320 } else { 640 })
    }

    pub fn trace_lod_steps(&self) -> usize {
        4 * (1 + 2 * STATES.len())
    }

    /// Runs the experiment.
    pub fn trace_lod(&self) -> Result<TraceLodResults> {
        let path = self.cfg.assets.join("cow").join("cow.obj");
        if !path.is_file() {
            let line = format!("trace-lod: {} is absent; seed 000's experiment did not run", path.display());
            return Ok((Vec::new(), Vec::new(), Some(line)));
        }
        let cow = load_obj(&path)?;
        let share = MIN_TRIANGLES as f32 / cow.triangle_count() as f32;
        let projection = self.trace_lod_projection();
        let base = RenderSettings::new(projection)
            .with_method(Method::Trace)
            .with_reflect_max(3)
            .with_light(Some(Vec3::new(0.0, LIGHT_HEIGHT, 0.0)));
        let gpu = &self.renderer.gpu;
        let mut points = Vec::new();
        let mut cow_chain = Vec::new();
        for (label, mirror, around) in [("A", true, true), ("B", false, true), ("C", true, false), ("D", false, false)]
        {
            let scene = scene(&cow, mirror, around)?;
            let chain = LodChain::build(&scene, share);
            if cow_chain.is_empty() {
                cow_chain =
                    chain.levels[0].iter().zip(&chain.errors[0]).map(|(l, &e)| ((l.len() / 3) as u32, e)).collect();
            }
            let plain = GpuScene::upload(gpu, &scene)?.with_bvh(gpu, &scene)?;
            let chained = GpuScene::upload(gpu, &scene)?.with_built_bvh(
                gpu,
                &scene.name,
                &SceneBvh::build(&scene.vertices, &chain.levels),
            )?;
            let runs: Vec<(&str, &str, &GpuScene, Option<Gaze>)> = std::iter::once((CONFIGS[0], "-", &plain, None))
                .chain(STATES.iter().flat_map(|&(state, yaw, pitch)| {
                    let g = Some(Gaze::new(yaw, pitch));
                    [(CONFIGS[1], state, &chained, g), (CONFIGS[2], state, &plain, g)]
                }))
                .collect();
            for (config, state, gs, gaze) in runs {
                self.progress.set_message(format!("trace-lod {label} {state} {config}"));
                let settings = base.with_trace_gaze(gaze).with_trace_min_share(share);
                let frame = |s: &RenderSettings| -> Result<Frame> { self.renderer.render(gs, s) };
                frame(&settings)?; // warm-up
                let frames: Vec<Frame> = (0..self.cfg.reps).map(|_| frame(&settings)).collect::<Result<_>>()?;
                let gpu_ms: Option<Vec<f64>> = frames.iter().map(|f| f.stats.ms_gpu).collect();
                let (ms, timing) = match gpu_ms {
                    Some(g) => (median(g), "gpu-timestamps"),
                    None => (median(frames.iter().map(|f| f.stats.ms_frame).collect()), "wall"),
                };
                let last = frames.last().expect("reps ≥ 1");
                let covered = frame(&settings.with_depth(true))?
                    .depth
                    .map_or(0, |d| d.iter().flatten().filter(|x| x.is_finite()).count() as u64);
                if label == "A" && config == "lod" {
                    let name = format!("trace_lod_A_{}.png", state.replace(' ', ""));
                    let img = image::RgbaImage::from_raw(last.left.width, last.left.height, last.left.rgba.clone())
                        .ok_or_else(|| Error::output(self.cfg.out.join(&name), "image size"))?;
                    write_png(&self.cfg.out.join(name), img)?;
                }
                self.progress.inc(1);
                points.push(TraceLodPoint {
                    scene: label.into(),
                    state: state.into(),
                    config: config.into(),
                    s_frame: ms / 1e3,
                    rays_traced: last.stats.rays_traced.unwrap_or(0),
                    triangle_tests: last.stats.triangle_tests.unwrap_or(0),
                    covered_pixels: covered,
                    timing: timing.into(),
                });
            }
        }
        Ok((points, cow_chain, None))
    }
}

/// The point of a scene, state and configuration.
fn find<'a>(points: &'a [TraceLodPoint], scene: &str, state: &str, config: &str) -> Option<&'a TraceLodPoint> {
    points.iter().find(|p| p.scene == scene && p.config == config && (config == "plain" || p.state == state))
}

pub fn plot(points: &[TraceLodPoint]) -> image::RgbaImage {
    let scenes = ["A", "B", "C", "D"];
    let ticks: Vec<(f64, String)> = scenes.iter().enumerate().map(|(k, s)| (k as f64, s.to_string())).collect();
    let ours = |config: &str, state: &str, color: usize, f: &dyn Fn(&TraceLodPoint, &TraceLodPoint) -> f64| Series {
        label: if config == "plain" { "plain".into() } else { format!("{config}, {state}") },
        color: PALETTE[color],
        points: scenes
            .iter()
            .enumerate()
            .filter_map(|(k, s)| {
                Some((k as f64, f(find(points, s, state, config)?, find(points, s, "", "plain")?), None))
            })
            .collect(),
        dashed: false,
        markers: true,
    };
    let seed = |label: &str, color: usize, f: &dyn Fn(&SeedRow) -> f64| Series {
        label: format!("seed 000: {label}"),
        color: PALETTE[color],
        points: SEED_TABLE_2.iter().enumerate().map(|(k, row)| (k as f64, f(row), None)).collect(),
        dashed: true,
        markers: true,
    };
    let seconds = Chart {
        title: "seconds per frame (this renderer)".into(),
        x_label: "scene".into(),
        y_label: "s".into(),
        x_ticks: ticks.clone(),
        series: vec![
            ours("plain", "-", 0, &|p, _| p.s_frame),
            ours("lod", "state 1", 1, &|p, _| p.s_frame),
            ours("lod", "state 2", 2, &|p, _| p.s_frame),
            ours("lod without eq. 10", "state 1", 3, &|p, _| p.s_frame),
        ],
        ..Default::default()
    };
    let share = Chart {
        title: "time with LOD / plain: ours vs seed 000".into(),
        x_label: "scene".into(),
        y_label: "share of plain".into(),
        x_ticks: ticks,
        series: vec![
            ours("lod", "state 1", 1, &|p, plain| p.s_frame / plain.s_frame),
            ours("lod", "state 2", 2, &|p, plain| p.s_frame / plain.s_frame),
            seed("state 1", 1, &|r| r.1 / r.3),
            seed("state 2", 2, &|r| r.2 / r.3),
        ],
        ..Default::default()
    };
    draw_panels(&[seconds, share], 2, 620, 460)
}

/// Writes trace_lod.csv, .json, .png and returns the report's section.
pub fn report(
    out: &Path,
    points: &[TraceLodPoint],
    chain: &[(u32, f32)],
    absent: Option<String>,
    projection: &Projection,
) -> Result<String> {
    if let Some(line) = absent {
        return Ok(format!("## Visual-field level of detail in ray tracing (seed 000, Table 2)\n\n- **{line}**\n\n"));
    }
    write_csv(&out.join("trace_lod.csv"), points)?;
    let json = serde_json::json!({ "points": points, "cow_chain": chain, "seed_table_2": SEED_TABLE_2 });
    twister::output::write_text(&out.join("trace_lod.json"), &serde_json::to_string_pretty(&json).unwrap())?;
    write_png(&out.join("trace_lod.png"), plot(points))?;
    let mut text = format!(
        "## Visual-field level of detail in ray tracing (seed 000, Table 2)\n\n![trace-lod](trace_lod.png)\n\n\
         Eight cows ({COW_TRIANGLES} triangles, N_min = {MIN_TRIANGLES}), a point light {LIGHT_HEIGHT} m above the eyes, \
         Reflect_max = 3; full-sphere ODS panorama {}×{} per eye, both eyes. A: mirror cows all around (four at eye level \
         every 90°, four 45° below between them, as on the seed's floor screen), B: diffuse all around, C: mirror ahead only \
         (within ±35°), D: diffuse ahead only. State 1 gazes ahead, state 2 60° down. `lod` is `--lod visual-field` \
         with `--method trace` (eq. 8–10); `lod without eq. 10` keeps every cow whole (untraced outside the field, fewer bounces only).\n\n\
         Seconds per frame, this renderer (seed 000 in parentheses, its 2007 CAVE cluster):\n\n| | A | B | C | D |\n|---|---|---|---|---|\n",
        projection.width, projection.height
    );
    let row = |label: &str, state: &str, config: &str, seed: &dyn Fn(&SeedRow) -> Option<f64>| {
        let mut r = format!("| {label} |");
        for s in &SEED_TABLE_2 {
            let ours = find(points, s.0, state, config).map_or("—".into(), |p| format!("{:.3}", p.s_frame));
            r += &match seed(s) {
                Some(v) => format!(" {ours} ({v:.3}) |"),
                None => format!(" {ours} |"),
            };
        }
        r + "\n"
    };
    text += &row("proposed (state 1)", "state 1", "lod", &|s| Some(s.1));
    text += &row("proposed (state 2)", "state 2", "lod", &|s| Some(s.2));
    text += &row("plain", "-", "plain", &|s| Some(s.3));
    text += &row("eq. 8–9 only (state 1)", "state 1", "lod without eq. 10", &|_| None);
    text += &row("eq. 8–9 only (state 2)", "state 2", "lod without eq. 10", &|_| None);
    text += &share_table(points);
    text += "\nRays traced and ray–triangle tests per frame:\n\n| scene | state | configuration | rays | triangle tests | tests per ray | pixels covered |\n|---|---|---|---|---|---|---|\n";
    for p in points {
        text += &format!(
            "| {} | {} | {} | {} | {} | {:.1} | {} |\n",
            p.scene,
            p.state,
            p.config,
            p.rays_traced,
            p.triangle_tests,
            p.triangle_tests as f64 / p.rays_traced.max(1) as f64,
            p.covered_pixels
        );
    }
    text += "\nThe cow's chain (meshoptimizer's quadric simplifier, each level about 0.7 of the one before; the seed used progressive \
             meshes, one triangle pair per step): triangles and the bound on how far a level lies from the original, as a share \
             of the cow's extent (neighbouring pixels whose rays pick different levels show surfaces this far apart at most):\n\n\
             | level | triangles | error bound |\n|---|---|---|\n";
    for (k, (triangles, error)) in chain.iter().enumerate() {
        text += &format!("| {k} | {triangles} | {:.2} % |\n", 100.0 * error);
    }
    text += "\nState 1, scene A, left eye, with LOD:\n\n![A, state 1](trace_lod_A_state1.png)\n\nState 2:\n\n![A, state 2](trace_lod_A_state2.png)\n\n";
    Ok(text)
}

/// Time with LOD as a share of plain tracing, per scene and state, beside seed 000's; and which
/// cases LOD made slower.
fn share_table(points: &[TraceLodPoint]) -> String {
    let mut text = String::new();
    text += "\nTime with LOD as a share of plain (seed 000 in parentheses; its best case 27.8 %, and 127 % / 114 % in A / B state 1, \
             where its polygon control cost more than it saved):\n\n| | A | B | C | D |\n|---|---|---|---|---|\n";
    let mut slower = Vec::new();
    for (state, seed_col) in [("state 1", 1), ("state 2", 2)] {
        let mut r = format!("| {state} |");
        for s in &SEED_TABLE_2 {
            let seed = if seed_col == 1 { s.1 } else { s.2 } / s.3;
            match (find(points, s.0, state, "lod"), find(points, s.0, state, "plain")) {
                (Some(l), Some(p)) => {
                    let share = l.s_frame / p.s_frame;
                    if share > 1.0 {
                        slower.push(format!("{} {state}", s.0));
                    }
                    r += &format!(" {:.1} % ({:.1} %) |", 100.0 * share, 100.0 * seed);
                }
                _ => r += " — |",
            }
        }
        text += &(r + "\n");
    }
    text += &if slower.is_empty() {
        "\nWith LOD no case is slower than plain tracing.\n".to_string()
    } else {
        format!("\n**Slower with LOD than plain: {}.**\n", slower.join(", "))
    };
    text
}
