//! Benchmarks, measured in release builds (never as timed tests).
//!
//! `speed`: for each scene and method, one warm-up frame, then the median of `reps` frames of
//! both eyes. A frame's time (`ms_frame`) is wall-clock from the first submission of its GPU
//! work (subdivision and the two-eye raster, with the counter read-back that checks the
//! buffers) until it completed; image read-back is apart. The split into subdivision and raster
//! comes from GPU timestamp queries where the adapter has them. Ratios are of `ms_frame`,
//! against the first method, in the same run.

use twister::core::settings::Method;
use twister::encoding::subdivide::{pass_group, PASS_GROUPS};
use twister::error::Result;
use twister::{FrameStats, GpuScene, RenderSettings, Renderer};

#[derive(Clone, Debug, serde::Serialize)]
pub struct SpeedRow {
    pub scene: String,
    pub method: String,
    pub triangles_in: u64,
    pub triangles_out: u64,
    /// triangles_out / triangles_in: how much the subdivision multiplies the input.
    pub out_per_in: f64,
    /// Vertices the vertex stage shades per eye: the subdivision's output nodes (its triangles
    /// index them); three per triangle drawn for the slit renderer (per slit it draws an object in).
    pub vertices_out: u64,
    pub pieces: u64,
    pub chunks: u32,
    pub max_sub_edge_px: f32,
    /// Median over the reps: wall time of the subdivision and raster of both eyes.
    pub ms_frame: f64,
    /// How the times were measured (`Timing`): GPU timestamps, or the wall clock.
    pub timing: String,
    /// Median GPU time of the frame, where timestamps were available.
    pub ms_gpu: Option<f64>,
    /// Median times of the subdivision and the raster, where they were measured apart.
    pub ms_subdivide: Option<f64>,
    /// Median times of each of the subdivision's passes, by its main entry point, in schedule
    /// order (`FrameStats::ms_subdivide_passes`), where timed.
    pub ms_subdivide_passes: Option<Vec<(&'static str, f64)>>,
    pub ms_raster: Option<f64>,
    pub ms_readback: f64,
    /// ms_frame / ms_frame of the first method on the same scene.
    pub ratio: f64,
    pub reps: usize,
    /// The balance of the subdivision's work (projection methods): invocations per entry point
    /// of its passes, in schedule order ...
    pub subdivide_invocations: Vec<(&'static str, u64)>,
    /// ... the most piece records one `plan` or `plan_cuts` invocation appended, the most nodes
    /// or triangles one `lattice` invocation wrote ...
    pub max_pieces_per_invocation: u32,
    pub max_output_per_invocation: u32,
    /// ... and the subdivision's share of the frame (ms_subdivide / (ms_subdivide + ms_raster)),
    /// where both were measured.
    pub subdivide_share: Option<f64>,
}

pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Renders a scene once with each of `settings` (the warm-up), then `reps` rounds of one frame
/// with each in turn, and returns each settings' frames' stats.
pub fn time_interleaved(
    renderer: &Renderer,
    scene: &GpuScene,
    settings: &[RenderSettings],
    reps: usize,
) -> Result<Vec<Vec<FrameStats>>> {
    for s in settings {
        renderer.render(scene, s)?;
    }
    let mut frames: Vec<Vec<FrameStats>> = settings.iter().map(|_| Vec::with_capacity(reps)).collect();
    for _ in 0..reps {
        for (s, out) in settings.iter().zip(&mut frames) {
            out.push(renderer.render(scene, s)?.stats);
        }
    }
    Ok(frames)
}

/// A scene of the `speed` benchmark, uploaded, with its settings (viewer, level of detail).
pub struct SpeedScene {
    pub spec: String,
    pub gpu_scene: GpuScene,
    pub settings: RenderSettings,
}

/// The `speed` benchmark: every scene with every method. A scene's methods are timed in turn,
/// frame by frame (after a warm-up frame of each), so that a change in the machine's load while
/// a scene is timed weighs on every method alike and their ratios compare like with like.
pub fn speed(
    renderer: &Renderer,
    scenes: &[SpeedScene],
    methods: &[Method],
    reps: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SpeedRow>> {
    let mut rows = Vec::new();
    for SpeedScene { spec, gpu_scene, settings: base } in scenes {
        let names: Vec<String> = methods.iter().map(|m| m.name()).collect();
        progress(&format!("{spec} {}", names.join(", ")));
        let settings: Vec<RenderSettings> = methods.iter().map(|&m| base.with_method(m)).collect();
        let timed = time_interleaved(renderer, gpu_scene, &settings, reps)?;
        let mut first_ms = None;
        for ((&method, settings), frames) in methods.iter().zip(&settings).zip(timed) {
            // The longest visible edge costs extra work: measured in one more, untimed frame.
            let edges = renderer.render(gpu_scene, &settings.with_measure_edges(true))?.stats;
            let ms_frame = median(frames.iter().map(|s| s.ms_frame).collect());
            let first = *first_ms.get_or_insert(ms_frame);
            let last = frames.last().expect("reps ≥ 1");
            let measured = |f: fn(&twister::FrameStats) -> Option<f64>| {
                let v: Vec<f64> = frames.iter().filter_map(f).collect();
                (v.len() == frames.len()).then(|| median(v))
            };
            rows.push(SpeedRow {
                scene: spec.clone(),
                method: method.name(),
                triangles_in: last.triangles_in,
                triangles_out: last.triangles_out,
                out_per_in: last.triangles_out as f64 / last.triangles_in.max(1) as f64,
                vertices_out: if last.nodes_out > 0 { last.nodes_out } else { 3 * last.triangles_out },
                pieces: last.pieces,
                chunks: last.chunks,
                max_sub_edge_px: edges.max_sub_edge_px,
                ms_frame,
                timing: last.timing.to_string(),
                ms_gpu: measured(|s| s.ms_gpu),
                ms_subdivide: measured(|s| s.ms_subdivide),
                ms_subdivide_passes: median_passes(&frames),
                ms_raster: measured(|s| s.ms_raster),
                ms_readback: median(frames.iter().map(|s| s.ms_readback).collect()),
                ratio: ms_frame / first,
                reps,
                subdivide_invocations: last.subdivide_invocations.clone(),
                max_pieces_per_invocation: last.max_pieces_per_invocation,
                max_output_per_invocation: last.max_output_per_invocation,
                subdivide_share: measured(|s| s.ms_subdivide)
                    .zip(measured(|s| s.ms_raster))
                    .map(|(sub, raster)| sub / (sub + raster).max(1e-9)),
            });
        }
    }
    Ok(rows)
}

/// The median of each pass's time over the frames, where every frame timed the same passes.
fn median_passes(frames: &[FrameStats]) -> Option<Vec<(&'static str, f64)>> {
    let first = frames.first()?.ms_subdivide_passes.as_ref()?;
    let mut times: Vec<Vec<f64>> = vec![Vec::with_capacity(frames.len()); first.len()];
    for f in frames {
        let passes = f.ms_subdivide_passes.as_ref().filter(|p| p.len() == first.len())?;
        for (k, ((label, ms), (first_label, _))) in passes.iter().zip(first).enumerate() {
            if label != first_label {
                return None;
            }
            times[k].push(*ms);
        }
    }
    Some(first.iter().zip(times).map(|(&(label, _), v)| (label, median(v))).collect())
}

/// The subdivision's time in its three groups (`encoding::subdivide::PASS_GROUPS`), from the
/// passes timed apart or in the groups.
fn pass_groups(passes: &[(&'static str, f64)]) -> [f64; 3] {
    let mut groups = [0.0; 3];
    for &(label, ms) in passes {
        groups[PASS_GROUPS.iter().position(|&g| g == pass_group(label)).expect("a group")] += ms;
    }
    groups
}

/// A Markdown table of the subdivision's balance: per scene and projection method, each
/// pass's invocations (with `each_pass`, where each pass was timed apart, its time: a setup
/// pass's with the pass it sets up), the largest output of one invocation, and its share of the
/// frame.
pub fn balance_table(rows: &[SpeedRow], each_pass: bool) -> String {
    let mut s = format!(
        "| scene | method | invocations per pass{} | max pieces / invocation | max nodes or triangles / invocation | subdivision's share |\n|---|---|---|---|---|---|\n",
        if each_pass { " (ms)" } else { "" }
    );
    for r in rows.iter().filter(|r| !r.subdivide_invocations.is_empty()) {
        let times = r.ms_subdivide_passes.iter().flatten().filter(|_| each_pass);
        let ms = |entry: &str| times.clone().find(|(label, _)| *label == entry).map(|p| p.1);
        let passes: Vec<String> = r
            .subdivide_invocations
            .iter()
            .map(|&(p, n)| ms(p).map_or(format!("{p} {n}"), |t| format!("{p} {n} ({t:.1})")))
            .collect();
        s += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            r.scene,
            r.method,
            passes.join(", "),
            r.max_pieces_per_invocation,
            r.max_output_per_invocation,
            r.subdivide_share.map_or("—".into(), |x| format!("{:.0} %", 100.0 * x)),
        );
    }
    s
}

/// A Markdown table of speed rows.
pub fn speed_table(rows: &[SpeedRow]) -> String {
    let mut s = String::from(
        "| scene | method | triangles in | triangles out | out / in | vertices per eye | ms frame (median) | ms subdivide (plan / cuts / lattice) | ms raster | ratio | max sub-edge px |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {} | {:.2} | {} | {:.1} | {} | {} | {:.2} | {:.1} |\n",
            r.scene,
            r.method,
            r.triangles_in,
            r.triangles_out,
            r.out_per_in,
            r.vertices_out,
            r.ms_frame,
            match (r.ms_subdivide, r.ms_subdivide_passes.as_deref().map(pass_groups)) {
                (Some(t), Some([plan, cuts, lattice])) => format!("{t:.1} ({plan:.1} / {cuts:.1} / {lattice:.1})"),
                (Some(t), None) => format!("{t:.1}"),
                _ => "—".into(),
            },
            r.ms_raster.map_or("—".into(), |t| format!("{t:.1}")),
            r.ratio,
            r.max_sub_edge_px
        );
    }
    s
}
