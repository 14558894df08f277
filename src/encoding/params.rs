//! Uniform builders: the parameters of the raster and trace stages, built from the settings
//! (the subdivide and slit stages' are in [`super::subdivide`] and [`super::slits`]).

use crate::core::display::{look_far, DisplayView};
use crate::core::panoramas::projection::Eye;
use crate::core::panoramas::projection::Projection;
use crate::core::settings::{RenderSettings, SplitRule};
use crate::encoding::types::{DisplayParams, RasterParams, TraceParams};

/// The raster stage's parameters: the left eye's, then the right's (its `array<RasterParams, 2>`).
pub fn raster_params(settings: &RenderSettings) -> [RasterParams; 2] {
    Eye::BOTH.map(|eye| RasterParams {
        projection: settings.projection().into(),
        eye_sign: eye.sign(),
        ambient: settings.shading.ambient,
        shift_px: settings.measure.shift_px,
        error_angle: settings.measure.error_angle as u32,
        w_by_radius: SplitRule::spaces_by_azimuth(settings.subdivision.method.split_rule().0 as u32) as u32,
        ..Default::default()
    })
}

/// The trace stage's parameters (`row_texels`: the outputs' padded row length).
pub fn trace_params(settings: &RenderSettings, row_texels: u32) -> TraceParams {
    let [r, g, b] = settings.shading.background;
    TraceParams {
        to_scene: settings.view().inverse().to_cols_array_2d(),
        projection: settings.projection().into(),
        background: [r, g, b, 1.0],
        light: settings.shading.light.map_or([0.0; 4], |l| [l.x, l.y, l.z, 1.0]),
        gaze_forward: settings.shading.trace_gaze.map_or([0.0; 4], |g| g.forward.extend(1.0).to_array()),
        gaze_right: settings.shading.trace_gaze.map_or([0.0; 4], |g| g.right.extend(0.0).to_array()),
        gaze_up: settings.shading.trace_gaze.map_or([0.0; 4], |g| g.up.extend(0.0).to_array()),
        ambient: settings.shading.ambient,
        error_angle: settings.measure.error_angle as u32,
        row_texels,
        reflect_max: settings.shading.reflect_max,
        lod_min_share: settings.shading.trace_min_share,
        // Set from the scene's BVH where it is bound (`SceneBvh::original_root`, `original_level`).
        original_root: 0,
        original_level: -1.0,
        samples: settings.shading.samples,
    }
}

/// The display stage's parameters for a frame of projection `p` shown as `view` (the live
/// window's `display` stage; twin `cpu::display`).
pub fn display_params(view: &DisplayView, p: &Projection) -> DisplayParams {
    let overlay = view.overlay.map_or([0.0; 4], |r| r.map(|v| v as f32));
    DisplayParams {
        projection: p.into(),
        mode: view.mode.code(),
        width: view.image[0],
        height: view.image[1],
        row_texels: view.row_texels,
        layers: view.layers,
        srgb_target: view.srgb_target as u32,
        _pad0: 0,
        _pad1: 0,
        area: view.area(),
        look: [view.look.yaw, view.look.pitch, (view.look.fov_deg.to_radians() / 2.0).tan(), look_far(p)],
        overlay,
    }
}
