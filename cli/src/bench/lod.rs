//! `twister bench lod`: seed 001's simulation on this renderer. Twelve Stanford bunnies (69,451
//! triangles each, 833,412 in all) stand around the viewer; the gaze sweeps through several
//! directions; for each, frames are drawn without the level of detail, with its polygon budgets
//! only, and with the polygon budgets and the relaxed subdivision (the full `--lod visual-field`):
//! triangles drawn, the time of the selection ("position test and shape redefinition": budgets,
//! chain levels, the new index list and its upload), of the subdivision and the drawing, and the
//! display-position error inside the central field (it must not get worse there) and outside it.
//!
//! The bunnies are 0.5 m tall, 3 m from the viewer every 30° of azimuth, at eye height. Their
//! triangles are far smaller than L, so the subdivision hardly splits them; a second ring of twelve
//! Sphere100s (1.4 m across, same places; built in), whose large triangles the subdivision splits
//! several times, shows what relaxing it saves. `--quick` uses the 948-triangle bunny, a quarter of
//! the resolution and two gazes.

use std::path::Path;
use std::time::Instant;
use twister::error::{Error, Result};

use glam::{Mat4, Vec3};
use serde::Serialize;

use crate::bench::runner::{write_csv, write_png, Runner};
use crate::bench::speed::median;
use crate::plot::{draw_panels, Chart, Series, PALETTE};
use twister::core::detail::lod::{LodChain, LodParams};
use twister::core::detail::visual_field::{Field, Gaze};
use twister::core::scenes::builtin::sphere_scene;
use twister::core::scenes::load::load_obj;
use twister::core::scenes::scene::Scene;
use twister::{Frame, GpuScene, RenderSettings};

/// Twelve copies of a model, `height` m tall, `radius` m around the viewer every 30°, at eye
/// height, each turned to face the viewer.
pub fn ring_of(model: &Scene, height: f32, radius: f32, name: &str) -> Result<Scene> {
    let (lo, hi) = model.bounds().ok_or_else(|| Error::scene(name, "the model has no triangles"))?;
    let s = height / (hi.y - lo.y);
    let centre = (lo + hi) / 2.0;
    let mut ring = Scene::new(name);
    for k in 0..12 {
        let azimuth = (30.0 * k as f32).to_radians();
        // Facing the viewer: the model's +z towards the origin.
        let m = Mat4::from_translation(Vec3::new(-radius * azimuth.sin(), 0.0, -radius * azimuth.cos()))
            * Mat4::from_rotation_y(azimuth)
            * Mat4::from_scale(Vec3::splat(s))
            * Mat4::from_translation(-centre);
        let mut one = model.clone();
        one.transform(m);
        ring.add_mesh(format!("{name} {k}"), &one.vertices, &one.indices);
    }
    Ok(ring)
}

/// The three ways a frame is drawn.
pub const CONFIGS: [&str; 3] = ["off", "polygons", "polygons+subdivision"];

/// One scene, gaze and configuration (`CONFIGS`).
#[derive(Clone, Debug, Serialize)]
pub struct LodPoint {
    pub scene: String,
    pub gaze_yaw: f32,
    pub gaze_pitch: f32,
    pub config: String,
    /// Triangles handed to the subdivision, and what it drew.
    pub triangles_in: u64,
    pub triangles_out: u64,
    pub ms_select: f64,
    pub ms_frame: f64,
    pub ms_total: f64,
    /// Display-position error over the pixels (both eyes) whose direction is in the central field.
    pub central_mean_px: f32,
    pub central_p99_px: f32,
    pub central_pixels: u64,
    /// The same over the other pixels (peripheral field and outside).
    pub other_mean_px: f32,
    pub timing: String,
}

/// Mean and p99 of the error over the central field's pixels of both eyes, their count, and
/// the mean over the other pixels.
fn field_errors(frame: &Frame, settings: &RenderSettings, gaze: &Gaze) -> (f32, f32, u64, f32) {
    let m = frame.measurement.as_ref().expect("measured");
    let p = &settings.view.projection;
    let (mut central, mut other) = (Vec::new(), Vec::new());
    for eye in &m.error {
        for (i, &e) in eye.iter().enumerate() {
            let (x, y) = ((i as u32 % p.width) as f32 + 0.5, (i as u32 / p.width) as f32 + 0.5);
            if e < 0.0 {
                continue;
            }
            if twister::core::detail::lod::pixel_field(p, gaze, x, y) == Field::Central {
                central.push(e);
            } else {
                other.push(e);
            }
        }
    }
    let mean = |v: &[f32]| {
        if v.is_empty() {
            f32::NAN
        } else {
            (v.iter().map(|&e| e as f64).sum::<f64>() / v.len() as f64) as f32
        }
    };
    central.sort_by(f32::total_cmp);
    let p99 = if central.is_empty() { f32::NAN } else { central[((central.len() - 1) as f64 * 0.99).round() as usize] };
    (mean(&central), p99, central.len() as u64, mean(&other))
}

impl Runner<'_> {
    /// The gazes swept: every 45° of yaw at eye level, and two pitched (quick: two gazes).
    fn gazes(&self) -> Vec<(f32, f32)> {
        if self.cfg.quick {
            vec![(0.0, 0.0), (90.0, 20.0)]
        } else {
            let mut g: Vec<(f32, f32)> = (0..8).map(|k| (45.0 * k as f32, 0.0)).collect();
            g.extend([(0.0, 30.0), (0.0, -30.0)]);
            g
        }
    }

    pub fn lod_steps(&self) -> usize {
        2 * CONFIGS.len() * self.gazes().len()
    }

    /// The rings measured: the bunnies (when the asset is there) and the spheres; the lines to
    /// report for what is absent.
    fn lod_scenes(&self) -> Result<(Vec<Scene>, Vec<String>)> {
        let file = if self.cfg.quick { "bun_zipper_res4.obj" } else { "bun_zipper.obj" };
        let path = self.cfg.assets.join("stanford-bunny").join(file);
        let mut scenes = Vec::new();
        let mut absent = Vec::new();
        if path.is_file() {
            scenes.push(ring_of(&load_obj(&path)?, 0.5, 3.0, "bunny")?);
        } else {
            absent.push(format!(
                "lod: {} is absent; the bunny ring of the level-of-detail benchmark did not run",
                path.display()
            ));
        }
        let sphere = sphere_scene(100, Vec3::ZERO, 0.5, "sphere");
        scenes.push(ring_of(&sphere, 1.4, 3.0, "sphere100")?);
        Ok((scenes, absent))
    }

    /// Runs the sweep on every ring; also returns the lines about absent assets.
    pub fn lod(&self) -> Result<(Vec<LodPoint>, Vec<String>)> {
        let (scenes, absent) = self.lod_scenes()?;
        let params = LodParams::default();
        let settings = RenderSettings::new(self.cfg.projection);
        let mut points = Vec::new();
        for (k, scene) in scenes.iter().enumerate() {
            let chain = LodChain::build(scene, params.p3);
            let base = GpuScene::upload(&self.renderer.gpu, scene)?;
            let ring =
                format!("12 × {} ({} triangles)", scene.objects[0].name.trim_end_matches(" 0"), scene.triangle_count());
            for (yaw, pitch) in self.gazes() {
                let gaze = Gaze::new(yaw, pitch);
                for config in CONFIGS {
                    self.progress.set_message(format!("lod {ring} gaze {yaw},{pitch} {config}"));
                    // One frame: selection (with LOD) then subdivision and drawing of both eyes.
                    let frame_once = |measure: bool| -> Result<(Frame, f64, f64)> {
                        let t = Instant::now();
                        let selected = (config != "off").then(|| {
                            let mut sel = chain.select(scene, settings.view(), &gaze, &params);
                            if config == "polygons" {
                                sel.chosen.iter_mut().for_each(|c| c.edge_scale = 1.0);
                            }
                            base.with_lod(&self.renderer.gpu, &sel)
                        });
                        let ms_select = t.elapsed().as_secs_f64() * 1e3;
                        let s = settings.with_measure_error(measure);
                        let frame = self.renderer.render(selected.as_ref().unwrap_or(&base), &s)?;
                        Ok((frame, ms_select, t.elapsed().as_secs_f64() * 1e3))
                    };
                    frame_once(false)?; // warm-up
                    let mut runs = Vec::new();
                    for _ in 0..self.cfg.reps {
                        runs.push(frame_once(false)?);
                    }
                    let gpu: Option<Vec<f64>> = runs.iter().map(|r| r.0.stats.ms_gpu).collect();
                    let (ms_frame, timing) = match gpu {
                        Some(g) => (median(g), "gpu-timestamps"),
                        None => (median(runs.iter().map(|r| r.0.stats.ms_frame).collect()), "wall"),
                    };
                    let (frame, _, _) = frame_once(true)?;
                    let (central_mean_px, central_p99_px, central_pixels, other_mean_px) =
                        field_errors(&frame, &settings, &gaze);
                    self.progress.inc(1);
                    points.push(LodPoint {
                        scene: ring.clone(),
                        gaze_yaw: yaw,
                        gaze_pitch: pitch,
                        config: config.into(),
                        triangles_in: frame.stats.triangles_in,
                        triangles_out: frame.stats.triangles_out,
                        ms_select: median(runs.iter().map(|r| r.1).collect()),
                        ms_frame,
                        ms_total: median(runs.iter().map(|r| r.2).collect()),
                        central_mean_px,
                        central_p99_px,
                        central_pixels,
                        other_mean_px,
                        timing: timing.into(),
                    });
                }
            }
            if k == 0 {
                // What the first gaze selected on the first ring, as `--lod-overlay` shows it (left eye).
                let gaze = Gaze::new(self.gazes()[0].0, self.gazes()[0].1);
                let sel = chain.select(scene, settings.view(), &gaze, &params);
                let mut tinted = scene.clone();
                twister::core::detail::lod::tint(&mut tinted, &sel);
                let shown = GpuScene::upload(&self.renderer.gpu, &tinted)?.with_lod(&self.renderer.gpu, &sel);
                let mut frame = self.renderer.render(&shown, &settings)?;
                twister::core::detail::lod::draw_field_boundaries(&mut frame.left, &settings.view.projection, &gaze);
                let img = image::RgbaImage::from_raw(frame.left.width, frame.left.height, frame.left.rgba)
                    .ok_or_else(|| Error::output(self.cfg.out.join("lod_overlay.png"), "overlay image size"))?;
                write_png(&self.cfg.out.join("lod_overlay.png"), img)?;
            }
        }
        Ok((points, absent))
    }
}

pub fn plot_lod(points: &[LodPoint]) -> image::RgbaImage {
    let mut rings: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    rings.dedup();
    let mut charts = Vec::new();
    for ring in rings {
        let of_ring: Vec<&LodPoint> = points.iter().filter(|p| p.scene == ring).collect();
        let series = |config: usize, f: &dyn Fn(&LodPoint) -> f64| Series {
            label: CONFIGS[config].into(),
            color: PALETTE[config],
            points: of_ring
                .iter()
                .filter(|p| p.config == CONFIGS[config])
                .enumerate()
                .map(|(k, p)| (k as f64, f(p), None))
                .collect(),
            dashed: config == 0,
            markers: true,
        };
        let ticks: Vec<(f64, String)> = of_ring
            .iter()
            .filter(|p| p.config == CONFIGS[0])
            .enumerate()
            .map(|(k, p)| (k as f64, format!("{},{}", p.gaze_yaw, p.gaze_pitch)))
            .collect();
        let chart = |title: &str, y: &str, f: &dyn Fn(&LodPoint) -> f64| Chart {
            title: format!("{ring}: {title}"),
            x_label: "gaze yaw,pitch [deg]".into(),
            y_label: y.into(),
            x_ticks: ticks.clone(),
            series: (0..CONFIGS.len()).map(|c| series(c, f)).collect(),
            ..Default::default()
        };
        charts.push(chart("triangles out", "triangles", &|p| p.triangles_out as f64));
        charts.push(chart("frame time", "ms", &|p| p.ms_select + p.ms_frame));
        charts.push(chart("central-field error (mean)", "px", &|p| p.central_mean_px as f64));
    }
    draw_panels(&charts, 3, 620, 460)
}

/// Writes lod.csv, lod.json, lod.png and returns the report's section.
pub fn report(out: &Path, points: &[LodPoint], absent: &[String]) -> Result<String> {
    write_csv(&out.join("lod.csv"), points)?;
    twister::output::write_text(&out.join("lod.json"), &serde_json::to_string_pretty(points).unwrap())?;
    write_png(&out.join("lod.png"), plot_lod(points))?;
    let mut text = String::from(
        "## Visual-field level of detail (seed 001)\n\n![lod](lod.png)\n\n![what the first gaze selected](lod_overlay.png)\n\n\
         The second image is the first ring's first gaze, left eye, as `--lod-overlay` shows it: objects tinted by level (green central, \
         yellow to red peripheral, dark red outside), the central field's boundary white, the visual field's orange.\n\n\
         Paper: 12 bunnies (833,412 triangles), mean 171,684 triangles drawn with the method (20.6 %), 0.119 s vs 0.330 s per frame \
         (2.8×). Configurations: `off`; `polygons` (the budgets of eq. 1–2 only); `polygons+subdivision` (also L relaxed by level, \
         no split outside the field: what `--lod visual-field` does).\n\n",
    );
    for line in absent {
        text += &format!("- **{line}**\n\n");
    }
    let mut rings: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    rings.dedup();
    for ring in rings {
        let mean = |config: &str, f: &dyn Fn(&LodPoint) -> f64| {
            let v: Vec<f64> = points.iter().filter(|p| p.scene == ring && p.config == config).map(f).collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        text += &format!(
            "### {ring}\n\nMean over the gazes:\n\n| configuration | triangles in | triangles out | select ms | frame ms (select + \
             subdivide + draw) | × faster than off | central-field error px | error elsewhere px |\n|---|---|---|---|---|---|---|---|\n"
        );
        let t_off = mean("off", &|p| p.ms_select + p.ms_frame);
        for config in CONFIGS {
            let t = mean(config, &|p| p.ms_select + p.ms_frame);
            text += &format!(
                "| {config} | {:.0} | {:.0} | {:.1} | {t:.1} | {:.2} | {:.4} | {:.4} |\n",
                mean(config, &|p| p.triangles_in as f64),
                mean(config, &|p| p.triangles_out as f64),
                mean(config, &|p| p.ms_select),
                t_off / t.max(1e-9),
                mean(config, &|p| p.central_mean_px as f64),
                mean(config, &|p| p.other_mean_px as f64),
            );
        }
        text += "\nPer gaze:\n\n| gaze yaw,pitch | configuration | triangles in | triangles out | select ms | frame ms | central error mean / p99 px | error elsewhere px |\n|---|---|---|---|---|---|---|---|\n";
        for p in points.iter().filter(|p| p.scene == ring) {
            text += &format!(
                "| {},{} | {} | {} | {} | {:.1} | {:.1} | {:.4} / {:.4} | {:.4} |\n",
                p.gaze_yaw,
                p.gaze_pitch,
                p.config,
                p.triangles_in,
                p.triangles_out,
                p.ms_select,
                p.ms_frame,
                p.central_mean_px,
                p.central_p99_px,
                p.other_mean_px
            );
        }
        text += "\n";
    }
    Ok(text)
}
