//! `twister error`: the display-position error of a method (seed 002 §4.1), as a summary or
//! JSON, with an optional heatmap and a comparison against another method.

use std::path::PathBuf;

use clap::Args;

use crate::args::ViewArgs;
use crate::scene::{lod_stats, open_renderer, prepare_loaded};
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::output::write_images;
use twister::EyeImage;

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct ErrorArgs {
    /// Scene: a .obj, .gltf or .glb file, or builtin:demo, builtin:box-room, builtin:cube, builtin:sphere100, builtin:sphere1024, builtin:triangle@D.
    #[arg(default_value = "builtin:demo")]
    pub scene: String,
    /// Move and scale the scene so that it stands DIST metres ahead, filling the screen height.
    #[arg(long, value_name = "DIST")]
    pub fit: Option<f32>,
    #[command(flatten)]
    pub view: ViewArgs,
    /// Print one JSON object instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Write the per-pixel error, colour-mapped with its scale, to this PNG (left eye on top).
    #[arg(long, value_name = "FILE.png")]
    pub heatmap: Option<PathBuf>,
    /// Top of the heatmap's scale in pixels (default: a round value at or above the p99 error).
    #[arg(long, value_name = "PX")]
    pub heatmap_max: Option<f32>,
    /// Also render with this method and report how much of the image shows a different surface,
    /// and the colour PSNR (e.g. --against slit:1).
    #[arg(long, value_parser = Method::parse, value_name = "METHOD")]
    pub against: Option<Method>,
}

/// One view's measurement: its settings, the `--json` object and each eye's per-pixel error.
pub struct Measured {
    pub wall: Option<String>,
    pub settings: twister::RenderSettings,
    pub json: serde_json::Value,
    /// Display-position error per pixel, left and right eye (−1: background or unseen).
    pub error: [Vec<f32>; 2],
    pub error_stats: twister::encoding::types::ErrorStats,
    pub frame_stats: twister::FrameStats,
}

/// What `error` measures, checked before anything is drawn: the settings and each view (one,
/// or a CAVE's walls: each its name and projection).
pub struct MeasurePlan {
    pub settings: twister::RenderSettings,
    pub views: Vec<(Option<String>, Option<twister::Projection>)>,
}

/// The measurement `args` ask for, every option checked.
pub fn plan_measure(args: &ErrorArgs) -> Result<MeasurePlan> {
    if let Some(max) = args.heatmap_max.filter(|m| !(m.is_finite() && *m > 0.0)) {
        return Err(Error::option("--heatmap-max", format!("must be a positive number of pixels, got {max}")));
    }
    // With --against, both frames also measure depth (the distance differences); against the ray
    // tracer, also the surface points (where the traced image shows what was drawn).
    let drawn: Vec<Method> = std::iter::once(args.view.method).chain(args.against).collect();
    let settings = args
        .view
        .settings(&drawn)?
        .with_measure_error(true)
        .with_depth(args.against.is_some())
        .with_positions(args.against == Some(Method::Trace));
    let walls = args.view.cave_walls(&settings)?;
    let views = if walls.is_empty() {
        vec![(None, None)]
    } else {
        walls.into_iter().map(|(name, p)| (Some(name), Some(p))).collect()
    };
    Ok(MeasurePlan { settings, views })
}

/// Measures each view of `plan`; `loaded`: the scene already loaded from `args.scene`.
pub fn measure_views(
    renderer: &twister::Renderer,
    adapter: &str,
    args: &ErrorArgs,
    plan: MeasurePlan,
    loaded: Option<&twister::Scene>,
) -> Result<Vec<Measured>> {
    let MeasurePlan { settings, views } = plan;
    let methods: Vec<Method> = std::iter::once(settings.subdivision.method).chain(args.against).collect();
    let prepared = prepare_loaded(renderer, &args.scene, loaded, args.fit, &args.view, settings, false, &methods)?;
    let gpu_scene = &prepared.gpu_scene;
    let mut measured = Vec::new();
    for (wall, projection) in views {
        let settings = match projection {
            Some(wall) => crate::cave::on_wall(prepared.settings, &wall),
            None => prepared.settings,
        };
        let frame = renderer.render(gpu_scene, &settings)?;
        let e = &frame.measurement.as_ref().expect("rendered with the error pass").stats;
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
            "lod": lod_stats(&prepared.selection),
            "triangles_in": s.triangles_in,
            "triangles_out": s.triangles_out,
            "ms_render": s.ms_frame,
            "timing": s.timing,
            "ms_total": s.ms_total,
            "adapter": adapter,
        });
        if let Some(wall) = &wall {
            json["wall"] = serde_json::json!(wall);
        }
        // On the sphere, pixels shrink towards the poles: the error is also measured as an angle
        // (seen from the centre), by a second render whose error pass writes arcminutes.
        if settings.view.projection.panorama.is_sphere() {
            let angular = renderer.render(gpu_scene, &settings.with_error_angle(true))?;
            add_angles(&mut json, &angular.measurement.as_ref().expect("rendered with the error pass").stats);
        }
        if let Some(method) = args.against {
            let reference = renderer.render(gpu_scene, &settings.with_method(method))?;
            add_comparison(&mut json, method, &twister::core::compare::compare(&frame, &reference)?);
        }
        let measurement = frame.measurement.expect("rendered with the error pass");
        measured.push(Measured {
            wall,
            settings,
            json,
            error: measurement.error,
            error_stats: measurement.stats,
            frame_stats: frame.stats,
        });
    }
    Ok(measured)
}

pub fn measure(args: &ErrorArgs) -> Result<()> {
    let heatmap = |wall: &Option<String>| {
        args.heatmap.as_ref().map(|path| match wall {
            Some(wall) => {
                path.with_file_name(format!("{wall}_{}", path.file_name().unwrap_or_default().to_string_lossy()))
            }
            None => path.clone(),
        })
    };
    let plan = plan_measure(args)?;
    // The heatmaps' files are checked before anything is drawn (a CAVE's named by wall).
    let heatmaps: Vec<std::path::PathBuf> = plan.views.iter().filter_map(|(wall, _)| heatmap(wall)).collect();
    twister::output::check_outputs(&heatmaps.iter().map(|p| p.as_path()).collect::<Vec<_>>())?;
    let (renderer, adapter) = open_renderer()?;
    for m in measure_views(&renderer, &adapter, args, plan, None)? {
        if let Some(path) = heatmap(&m.wall) {
            let max = args.heatmap_max.unwrap_or_else(|| crate::heatmap::nice_max(m.error_stats.p99));
            write_heatmap(&path, &m.error, m.settings.projection(), max)?;
        }
        if args.json {
            println!("{}", serde_json::to_string(&m.json).unwrap());
        } else {
            let scene = match &m.wall {
                Some(wall) => format!("{} wall {wall}", args.scene),
                None => args.scene.clone(),
            };
            print_summary(&scene, &m.settings, &m.json, &m.error_stats, &m.frame_stats);
        }
    }
    Ok(())
}

/// The error as an angle (arcminutes seen from the centre), on the sphere.
fn add_angles(json: &mut serde_json::Value, a: &twister::encoding::types::ErrorStats) {
    json["panorama"] = serde_json::json!("equirect");
    json["mean_arcmin"] = serde_json::json!(a.mean);
    json["p50_arcmin"] = serde_json::json!(a.p50);
    json["p90_arcmin"] = serde_json::json!(a.p90);
    json["p99_arcmin"] = serde_json::json!(a.p99);
    json["max_arcmin"] = serde_json::json!(a.max);
}

/// `--against`: the comparison with the other method's frame (and the error found on a traced one).
fn add_comparison(json: &mut serde_json::Value, method: Method, c: &twister::core::compare::Comparison) {
    json["against"] = serde_json::json!(method.name());
    json["different_surface_fraction"] = serde_json::json!(c.different_surface_fraction);
    json["psnr_db"] = serde_json::json!(c.psnr_db);
    json["depth_rel_mean"] = serde_json::json!(c.depth_rel_mean);
    json["depth_rel_p99"] = serde_json::json!(c.depth_rel_p99);
    json["different_triangle_fraction"] = serde_json::json!(c.different_triangle_fraction);
    if let Some(t) = &c.traced_error {
        json["traced_mean_px"] = serde_json::json!(t.mean_px);
        json["traced_p99_px"] = serde_json::json!(t.p99_px);
        json["traced_max_px"] = serde_json::json!(t.max_px);
        json["traced_pixels"] = serde_json::json!(t.pixels);
        json["traced_unmatched"] = serde_json::json!(t.unmatched);
    }
}

/// `--heatmap FILE.png`: the per-pixel error (left eye on top) colour-mapped up to `max` pixels.
fn write_heatmap(
    path: &std::path::Path,
    error: &[Vec<f32>; 2],
    projection: &twister::Projection,
    max: f32,
) -> Result<()> {
    let (w, h, rgba) = crate::heatmap::heatmap(error, projection.width, projection.height, max);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "heatmap.png".into());
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    write_images(dir, &[(name, EyeImage { width: w, height: h, rgba })]).map(|_| ())
}

/// The measurement in words (without `--json`).
fn print_summary(
    scene: &str,
    settings: &twister::RenderSettings,
    json: &serde_json::Value,
    e: &twister::encoding::types::ErrorStats,
    s: &twister::FrameStats,
) {
    println!(
            "{} {} ({}): mean {:.3} px, std {:.3}, p50 {:.3}, p90 {:.3}, p99 {:.3}, max {:.3} over {} pixels; {} triangles drawn; {:.1} ms",
            scene,
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
    if let Some(m) = json.get("mean_arcmin") {
        println!(
            "as an angle: mean {:.3}′, p50 {:.3}′, p90 {:.3}′, p99 {:.3}′, max {:.3}′ (arcminutes)",
            m.as_f64().unwrap_or(f64::NAN),
            json["p50_arcmin"].as_f64().unwrap_or(f64::NAN),
            json["p90_arcmin"].as_f64().unwrap_or(f64::NAN),
            json["p99_arcmin"].as_f64().unwrap_or(f64::NAN),
            json["max_arcmin"].as_f64().unwrap_or(f64::NAN)
        );
    }
    if json.get("different_surface_fraction").is_some() {
        let num = |k: &str| json[k].as_f64().map_or("—".to_string(), |v| format!("{v:.3e}"));
        println!(
                "against {}: different surface on {} of pixels (another triangle of the same object on {}), PSNR {} dB, distance off by {} (mean) / {} (p99) of the reference's",
                json["against"].as_str().unwrap_or(""),
                num("different_surface_fraction"),
                num("different_triangle_fraction"),
                json["psnr_db"].as_f64().map_or("∞".to_string(), |v| format!("{v:.2}")),
                num("depth_rel_mean"),
                num("depth_rel_p99")
            );
    }
    if let Some(m) = json.get("traced_mean_px") {
        println!(
                "display-position error measured on the traced image: mean {:.3} px, p99 {:.3}, max {:.3} over {} pixels ({} not found there)",
                m.as_f64().unwrap_or(f64::NAN),
                json["traced_p99_px"].as_f64().unwrap_or(f64::NAN),
                json["traced_max_px"].as_f64().unwrap_or(f64::NAN),
                json["traced_pixels"],
                json["traced_unmatched"]
            );
    }
}
