//! The promises checked on each search case: the settings are valid, the CPU twin's
//! subdivision is watertight and loses nothing ([`super::topology`]), the real renderer shows
//! no background pixel, and the GPU's subdivision is the twin's ([`super::twin`]).

use super::{topology, twin, SearchCase, SearchPanorama};
use crate::core::detail::lod::LodSelection;
use crate::core::scenes::scene::Scene;
use crate::core::settings::RenderSettings;
use crate::encoding::schedule::{Capacities, Schedule};
use crate::encoding::subdivide::subdivide_params;
use crate::gpu::{GpuScene, Renderer};

/// Which promise a case broke.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Check {
    /// A panic anywhere in the case's checks (never allowed).
    Panic,
    Settings,
    Topology,
    Background,
    Twin,
}

impl Check {
    pub fn name(self) -> &'static str {
        match self {
            Check::Panic => "panic",
            Check::Settings => "settings",
            Check::Topology => "topology",
            Check::Background => "background",
            Check::Twin => "twin",
        }
    }
}

/// A broken promise: which, and one line saying how.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub check: Check,
    pub message: String,
}

/// The case's scene, the scene as its frame draws it (its level-of-detail selection applied),
/// its settings and the selection.
pub type Drawn = (Scene, Scene, RenderSettings, Option<LodSelection>);

/// A case's [`Drawn`] (its level-of-detail chain built once for all its checks).
pub fn drawn_scene(case: &SearchCase) -> Drawn {
    let scene = case.scene();
    let settings = case.settings();
    let lod = case.lod(&scene, &settings);
    let drawn = lod.as_ref().map_or_else(|| scene.clone(), |sel| sel.scene(&scene));
    (scene, drawn, settings, lod)
}

/// The CPU's promises: the settings are valid and the twin's subdivision is watertight and
/// whole.
pub fn check_cpu(case: &SearchCase, (_, scene, settings, lod): &Drawn) -> Result<(), Failure> {
    settings.validate().map_err(|e| Failure { check: Check::Settings, message: e.to_string() })?;
    if case.panorama == SearchPanorama::Cave {
        return Ok(()); // drawn without subdivision: its promise is the GPU's (no background)
    }
    let scales = lod.as_ref().map(|sel| sel.edge_scales()).unwrap_or_default();
    let topology = topology::Topology {
        vertices: &scene.vertices,
        indices: &scene.indices,
        params: subdivide_params(settings, 0, scene.triangle_count() as u32),
        edge_scale: &scales,
    };
    topology
        .check(16, scene.triangle_count() as u64)
        .map(|_| ())
        .map_err(|message| Failure { check: Check::Topology, message })
}

/// The GPU's promises: no background pixel in either eye (inside the fisheye's circle), and the
/// GPU's subdivision equal to the twin's (the usual frame's schedule).
pub fn check_gpu(
    renderer: &Renderer,
    case: &SearchCase,
    (original, scene, settings, lod): &Drawn,
) -> Result<(), Failure> {
    let fail = |check| move |e: crate::error::Error| Failure { check, message: e.to_string() };
    let mut gs = GpuScene::upload(&renderer.gpu, original).map_err(fail(Check::Background))?;
    if let Some(sel) = lod {
        gs = gs.with_lod(&renderer.gpu, sel);
    }
    let frame = renderer.render(&gs, settings).map_err(fail(Check::Background))?;
    let projection = settings.projection();
    for (eye, image) in [("left", &frame.left), ("right", &frame.right)] {
        let mut seen = Vec::new();
        for y in 0..image.height {
            for x in 0..image.width {
                let p = image.pixel(x, y);
                let marker = p[0] >= 254 && p[1] <= 1 && p[2] >= 254;
                if marker && projection.shows_pixel(x as f32 + 0.5, y as f32 + 0.5) {
                    seen.push((x, y));
                }
            }
        }
        if !seen.is_empty() {
            return Err(Failure {
                check: Check::Background,
                message: format!(
                    "{eye} eye: {} pixels show the background, e.g. {:?}",
                    seen.len(),
                    &seen[..seen.len().min(4)]
                ),
            });
        }
    }
    // A CAVE wall is drawn without subdivision (one perspective per eye): nothing to compare.
    if case.panorama != SearchPanorama::Cave {
        let scales = lod.as_ref().map(|sel| sel.edge_scales()).unwrap_or_default();
        let gpu = renderer.subdivide_readback(&gs, settings, Schedule::OneSubmission).map_err(fail(Check::Twin))?;
        let budget = Capacities::budget(settings.subdivision.memory_mb, renderer.gpu.max_binding());
        let cpu = crate::cpu::subdivide::passes::run_scheduled(
            settings,
            &scene.vertices,
            &scene.indices,
            &scales,
            Schedule::OneSubmission,
            budget,
        )
        .map_err(fail(Check::Twin))?;
        let software = renderer.gpu.info.device_type == wgpu::DeviceType::Cpu;
        twin::compare_subdivided(&gpu, &cpu, software).map_err(|message| Failure { check: Check::Twin, message })?;
    }
    Ok(())
}

/// Every check of a case: the CPU's, then (with a renderer) the GPU's; a panic in either is a
/// failure of its own.
pub fn check(renderer: Option<&Renderer>, case: &SearchCase) -> Result<(), Failure> {
    let run = || {
        let drawn = drawn_scene(case);
        check_cpu(case, &drawn)?;
        renderer.map_or(Ok(()), |r| check_gpu(r, case, &drawn))
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "a panic".into());
        Err(Failure { check: Check::Panic, message })
    })
}
