//! `twister bench fig8|fig10|fig12|all`: the paper's three evaluations (seed 002 §4) on this
//! project, as CSV and JSON of every point, PNG plots and a `report.md` with the paper's
//! numbers beside ours.
//!
//! - **fig8** (Fig. 8): `builtin:triangle@1`, `@3`, `@5` with `fixed:N`, N = 1..10: mean and std
//!   of the display-position error.
//! - **fig10** (Fig. 10): Sphere100, Sphere1024, the 16,301-triangle bunny (3 m ahead, filling the
//!   screen height) and the Sponza atrium (viewer inside at standing height) with `adaptive:length`, `adaptive`,
//!   `fixed:1..7` and `vertex`: error (mean, std, p99), frame time for both eyes, output triangles.
//! - **fig12** (Fig. 12): `slit:W`, W = 1, 2, 4, …, 128 against `adaptive:length` (the paper's
//!   eq. 5) and `adaptive` (the error split) on the fig10 scenes: time and error, and the matched
//!   width w* at which slits take as long as each
//!   (interpolated between the measured widths with log W linear in log time).
//!
//! Times: median of `reps` frames after a warm-up. The frame time is the GPU time from timestamp
//! queries where the adapter has them (start of the first pass to the end of the last, for every
//! method alike), else wall time around submit-and-wait; the report says which. Errors come from
//! one more frame with the error pass on. Assets missing from the assets folder are skipped with
//! a line in the report.

use twister::error::Result;

use glam::Vec3;
use serde::Serialize;

use crate::bench::runner::{FigureConfig, Runner};
use crate::bench::speed::median;
use crate::plot::{draw_panels, Chart, Series, PALETTE};
use twister::core::panoramas::projection::{Projection, Vertical};
use twister::core::scenes::load::load_scene;
use twister::core::scenes::scene::Scene;
use twister::core::settings::{Method, Split};
use twister::{GpuScene, RenderSettings};

/// A scene of the fig10/fig12 evaluations, placed.
pub struct Case {
    pub label: String,
    pub scene: Scene,
    pub viewer: Vec3,
}

/// The fig10 scenes present, and a line for each one skipped.
pub fn cases(cfg: &FigureConfig) -> Result<(Vec<Case>, Vec<String>)> {
    let p = &cfg.projection;
    let mut cases = vec![
        Case { label: "Sphere100".into(), scene: load_scene("builtin:sphere100", p)?, viewer: Vec3::ZERO },
        Case { label: "Sphere1024".into(), scene: load_scene("builtin:sphere1024", p)?, viewer: Vec3::ZERO },
    ];
    let mut skipped = Vec::new();
    let bunny = cfg.assets.join("stanford-bunny/bun_zipper_res2.obj");
    if bunny.exists() {
        let mut scene = load_scene(&bunny.to_string_lossy(), p)?;
        scene.fit(3.0, p)?;
        cases.push(Case { label: "Bunny".into(), scene, viewer: Vec3::ZERO });
    } else {
        skipped.push(format!("Bunny skipped: {} is absent", bunny.display()));
    }
    let sponza = cfg.assets.join("sponza-dabrovic/sponza.obj");
    if sponza.exists() {
        // The atrium's floor is at y ≈ 0.1 m: the viewer stands in the middle of the courtyard.
        let scene = load_scene(&sponza.to_string_lossy(), p)?;
        cases.push(Case { label: "Sponza".into(), scene, viewer: Vec3::new(0.0, 1.7, 0.0) });
    } else {
        skipped.push(format!("Sponza skipped: {} is absent", sponza.display()));
    }
    Ok((cases, skipped))
}

/// One measured point.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub scene: String,
    pub method: String,
    /// N of fixed:N, W of slit:W, 0 otherwise.
    pub parameter: u32,
    pub mean_px: f32,
    pub std_px: f32,
    pub p99_px: f32,
    pub max_px: f32,
    pub pixels: u32,
    pub ms_frame: f64,
    pub triangles_out: u64,
    pub timing: String,
}

/// The width at which slits take as long as `adaptive` on a scene.
#[derive(Clone, Debug, Serialize)]
pub struct Matched {
    pub scene: String,
    /// The adaptive method matched (`adaptive:length`, the paper's, or `adaptive`).
    pub method: String,
    pub adaptive_ms: f64,
    pub w_star: Option<f64>,
    pub note: String,
}

impl Runner<'_> {
    /// Times the methods of one scene (after a warm-up frame of each, `reps` rounds of one frame
    /// per method in turn: see `bench::speed::time_interleaved`; the median of each) and
    /// measures each one's error (one more frame). `methods`: each with its figure parameter.
    fn points(
        &self,
        label: &str,
        gpu_scene: &GpuScene,
        viewer: Vec3,
        methods: &[(Method, u32)],
        time: bool,
        vertical: Vertical,
    ) -> Result<Vec<Point>> {
        let names: Vec<String> = methods.iter().map(|(m, _)| m.name()).collect();
        self.progress.set_message(format!("{label} {}", names.join(", ")));
        let projection = Projection { vertical, ..self.cfg.projection };
        let settings: Vec<RenderSettings> =
            methods.iter().map(|&(m, _)| RenderSettings::new(projection).with_viewer(viewer).with_method(m)).collect();
        let timed = if time {
            crate::bench::speed::time_interleaved(self.renderer, gpu_scene, &settings, self.cfg.reps)?
        } else {
            vec![Vec::new(); settings.len()]
        };
        let mut out = Vec::with_capacity(methods.len());
        for ((&(method, parameter), settings), frames) in methods.iter().zip(&settings).zip(timed) {
            let (ms_frame, timing) = if !time {
                (f64::NAN, "-")
            } else {
                match frames.iter().map(|f| f.ms_gpu).collect::<Option<Vec<f64>>>() {
                    Some(gpu) => (median(gpu), "gpu-timestamps"),
                    None => (median(frames.iter().map(|f| f.ms_frame).collect()), "wall"),
                }
            };
            let frame = self.renderer.render(gpu_scene, &settings.with_measure_error(true))?;
            let e = frame.measurement.expect("measured").stats;
            self.progress.inc(1);
            out.push(Point {
                scene: label.to_string(),
                method: method.name(),
                parameter,
                mean_px: e.mean,
                std_px: e.std_dev,
                p99_px: e.p99,
                max_px: e.max,
                pixels: e.count,
                ms_frame,
                triangles_out: frame.stats.triangles_out,
                timing: timing.to_string(),
            });
        }
        Ok(out)
    }

    pub fn fig8(&self) -> Result<Vec<Point>> {
        let mut out = Vec::new();
        for d in [1, 3, 5] {
            let scene = load_scene(&format!("builtin:triangle@{d}"), &self.cfg.projection)?;
            let gpu_scene = GpuScene::upload(&self.renderer.gpu, &scene)?;
            let methods: Vec<(Method, u32)> =
                self.cfg.fig8_divisions().into_iter().map(|n| (Method::Fixed(n), n)).collect();
            out.extend(self.points(
                &format!("triangle@{d}"),
                &gpu_scene,
                Vec3::ZERO,
                &methods,
                false,
                Vertical::Paper,
            )?);
        }
        Ok(out)
    }

    pub fn fig10(&self, cases: &[Case]) -> Result<Vec<Point>> {
        let mut out = Vec::new();
        for case in cases {
            let gpu_scene = GpuScene::upload(&self.renderer.gpu, &case.scene)?;
            let methods: Vec<(Method, u32)> = self
                .cfg
                .fig10_methods()
                .into_iter()
                .map(|m| (m, if let Method::Fixed(n) = m { n } else { 0 }))
                .collect();
            out.extend(self.points(&case.label, &gpu_scene, case.viewer, &methods, true, Vertical::Paper)?);
        }
        Ok(out)
    }

    pub fn fig12(&self, cases: &[Case]) -> Result<(Vec<Point>, Vec<Matched>)> {
        let (mut out, mut matched) = (Vec::new(), Vec::new());
        for case in cases {
            let gpu_scene = GpuScene::upload(&self.renderer.gpu, &case.scene)?;
            // Slits converge to the exact vertical model: every fig12 error is measured in it.
            // Both adaptive rules and every slit width timed in turn.
            let mut methods: Vec<(Method, u32)> =
                [Split::Length, Split::Error].into_iter().map(|split| (Method::Adaptive(split), 0)).collect();
            methods.extend(self.cfg.slit_widths().into_iter().map(|w| (Method::Slit(w), w)));
            let mut points = self.points(&case.label, &gpu_scene, case.viewer, &methods, true, Vertical::Exact)?;
            let slits = points.split_off(2);
            let adaptive = points;
            for a in &adaptive {
                matched.push(match_width(&case.label, &a.method, a.ms_frame, &slits));
            }
            out.extend(adaptive);
            out.extend(slits);
        }
        Ok((out, matched))
    }
}

/// The slit width at which slits take as long as adaptive, log W interpolated linearly in log
/// time between the two measured widths around it.
pub fn match_width(scene: &str, method: &str, adaptive_ms: f64, slits: &[Point]) -> Matched {
    let pts: Vec<(f64, f64)> = slits.iter().map(|p| (p.parameter as f64, p.ms_frame)).collect();
    let mut w_star = None;
    for w in pts.windows(2) {
        let ((w0, t0), (w1, t1)) = (w[0], w[1]);
        if (t0 - adaptive_ms) * (t1 - adaptive_ms) <= 0.0 && t0 != t1 {
            let f = (adaptive_ms.ln() - t0.ln()) / (t1.ln() - t0.ln());
            w_star = Some((w0.ln() + f * (w1.ln() - w0.ln())).exp());
            break;
        }
    }
    let note = match (w_star, pts.first(), pts.last()) {
        (Some(w), _, _) => format!("slits of {w:.1} px take as long as adaptive"),
        (None, Some(&(w, t)), _) if t <= adaptive_ms => format!("even slit:{w} is as fast as adaptive: no advantage"),
        (None, _, Some(&(w, _))) => format!("adaptive is faster than every slit width up to {w} px"),
        _ => "no slit widths measured".into(),
    };
    Matched { scene: scene.to_string(), method: method.to_string(), adaptive_ms, w_star, note }
}

fn series_by_scene(
    points: &[Point],
    x: impl Fn(&Point) -> Option<f64>,
    y: impl Fn(&Point) -> (f64, Option<f64>),
) -> Vec<Series> {
    let mut scenes: Vec<&str> = Vec::new();
    for p in points {
        if !scenes.contains(&p.scene.as_str()) {
            scenes.push(&p.scene);
        }
    }
    scenes
        .iter()
        .enumerate()
        .map(|(i, s)| Series {
            label: s.to_string(),
            points: points
                .iter()
                .filter(|p| p.scene == *s)
                .filter_map(|p| {
                    let (yv, e) = y(p);
                    x(p).map(|xv| (xv, yv, e))
                })
                .collect(),
            color: PALETTE[i % PALETTE.len()],
            dashed: false,
            markers: true,
        })
        .collect()
}

/// Position of a fig10 method on the x axis: vertex, fixed:1..7, adaptive:length, adaptive.
fn method_x(p: &Point) -> Option<f64> {
    match p.method.as_str() {
        "vertex" => Some(0.0),
        "adaptive:length" => Some(8.0),
        "adaptive" => Some(9.0),
        m if m.starts_with("fixed:") => Some(p.parameter as f64),
        _ => None,
    }
}

pub fn plot_fig8(points: &[Point]) -> image::RgbaImage {
    let chart = Chart {
        title: "Fig. 8: display-position error vs edge divisions N (fixed:N)".into(),
        x_label: "edge division count N".into(),
        y_label: "error [px] (mean ± std)".into(),
        y_log: true,
        series: series_by_scene(points, |p| Some(p.parameter as f64), |p| (p.mean_px as f64, Some(p.std_px as f64))),
        ..Default::default()
    };
    draw_panels(&[chart], 1, 900, 560)
}

pub fn plot_fig10(points: &[Point]) -> image::RgbaImage {
    let ticks: Vec<(f64, String)> = std::iter::once((0.0, "vertex".to_string()))
        .chain((1..=7).map(|n| (n as f64, format!("fixed:{n}"))))
        .chain([(8.0, "eq. 5".into()), (9.0, "error".into())])
        .collect();
    let error = Chart {
        title: "Fig. 10 (left): display-position error".into(),
        x_label: "method (eq. 5: adaptive:length; error: adaptive, the error split)".into(),
        y_label: "error [px] (mean ± std)".into(),
        y_log: true,
        x_ticks: ticks.clone(),
        series: series_by_scene(points, method_x, |p| (p.mean_px as f64, Some(p.std_px as f64))),
        ..Default::default()
    };
    let time = Chart {
        title: "Fig. 10 (right): time per frame, both eyes".into(),
        x_label: "method (eq. 5: adaptive:length; error: adaptive, the error split)".into(),
        y_label: "ms per frame".into(),
        y_log: true,
        x_ticks: ticks,
        series: series_by_scene(points, method_x, |p| (p.ms_frame, None)),
        ..Default::default()
    };
    draw_panels(&[error, time], 2, 820, 560)
}

pub fn plot_fig12(points: &[Point]) -> image::RgbaImage {
    let slit = |p: &Point| p.method.starts_with("slit:").then_some(p.parameter as f64);
    let mut time = series_by_scene(points, slit, |p| (p.ms_frame, None));
    let mut error = series_by_scene(points, slit, |p| (p.mean_px as f64, None));
    let widths: Vec<f64> = points.iter().filter_map(slit).collect();
    let (lo, hi) = widths.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &w| (a.min(w), b.max(w)));
    for (series, value) in [(&mut time, 0usize), (&mut error, 1)] {
        let extra: Vec<Series> = series
            .iter()
            .flat_map(|s| ["adaptive:length", "adaptive"].map(|m| (s, m)))
            .filter_map(|(s, method)| {
                let a = points.iter().find(|p| p.scene == s.label && p.method == method)?;
                let y = if value == 0 { a.ms_frame } else { a.mean_px as f64 };
                Some(Series {
                    label: format!("{} {method}", s.label),
                    points: vec![(lo, y, None), (hi, y, None)],
                    color: s.color,
                    dashed: true,
                    markers: false,
                })
            })
            .collect();
        series.extend(extra);
    }
    let ticks: Vec<(f64, String)> = widths.iter().map(|w| (*w, format!("{w}"))).collect();
    let charts = [
        Chart {
            title: "Fig. 12: time per frame vs slit width (dashed: adaptive)".into(),
            x_label: "slit width W [px]".into(),
            y_label: "ms per frame".into(),
            x_log: true,
            y_log: true,
            x_ticks: ticks.clone(),
            series: time,
        },
        Chart {
            title: "Mean display-position error vs slit width (dashed: adaptive)".into(),
            x_label: "slit width W [px]".into(),
            y_label: "mean error [px]".into(),
            x_log: true,
            y_log: true,
            x_ticks: ticks,
            series: error,
        },
    ];
    draw_panels(&charts, 2, 820, 560)
}

pub fn table(points: &[Point], with_time: bool) -> String {
    let mut s = if with_time {
        String::from("| scene | method | mean px | std px | p99 px | ms/frame | triangles out |\n|---|---|---|---|---|---|---|\n")
    } else {
        String::from("| scene | method | mean px | std px | p99 px | pixels |\n|---|---|---|---|---|---|\n")
    };
    for p in points {
        if with_time {
            s += &format!(
                "| {} | {} | {:.3} | {:.3} | {:.3} | {:.1} | {} |\n",
                p.scene, p.method, p.mean_px, p.std_px, p.p99_px, p.ms_frame, p.triangles_out
            );
        } else {
            s += &format!(
                "| {} | {} | {:.3} | {:.3} | {:.3} | {} |\n",
                p.scene, p.method, p.mean_px, p.std_px, p.p99_px, p.pixels
            );
        }
    }
    s
}
