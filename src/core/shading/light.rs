//! Lights and the glTF look (issue 17, first part): punctual lights as `KHR_lights_punctual`
//! defines them, the lighting mode, and the tone mapping of the linear colour.
//!
//! A light's colour is its linear colour × intensity: candela (lm/sr) for point and spot
//! lights, lux (lm/m²) for directional ones. A point or spot light at distance d lights a surface
//! with colour / d², times the glTF range window (1 − (d/range)⁴)² when a range is given; a spot
//! light also by its cone: ((cos θ − cos outer) / (cos inner − cos outer))², clamped to 0..1.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::core::shading::environment::{PreparedEnvironment, ENV_LEVELS};

/// `LIGHT_*` in the WGSL `constants` module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Directional = 0,
    Point = 1,
    Spot = 2,
}

/// A punctual light in scene coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub position: Vec3,
    /// The unit direction the light shines along (directional and spot).
    pub direction: Vec3,
    /// Linear colour × intensity.
    pub color: Vec3,
    /// Distance beyond which it lights nothing (point and spot); None: unlimited.
    pub range: Option<f32>,
    /// Cone half-angles of a spot light, radians (inner ≤ outer).
    pub inner_cone: f32,
    pub outer_cone: f32,
}

impl Light {
    /// A sun: a directional light of `lux` shining from azimuth `azimuth_deg` (from −z towards
    /// +x, as the panorama's u) and `elevation_deg` above the horizon (`--sun`).
    pub fn sun(azimuth_deg: f32, elevation_deg: f32, lux: f32) -> Light {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let towards = Vec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos());
        Light {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: -towards,
            color: Vec3::splat(lux),
            range: None,
            inner_cone: 0.0,
            outer_cone: 0.0,
        }
    }

    /// The light moved by `m` (a rigid transform: a node's world matrix or the view).
    pub fn transformed(&self, m: Mat4) -> Light {
        Light {
            position: m.transform_point3(self.position),
            direction: m.transform_vector3(self.direction).normalize_or_zero(),
            ..*self
        }
    }

    /// As the fragment stage reads it.
    pub fn gpu(&self) -> GpuLight {
        GpuLight {
            position: self.position.to_array(),
            kind: self.kind as u32,
            direction: self.direction.to_array(),
            range: self.range.unwrap_or(0.0),
            color: self.color.to_array(),
            inner_cos: self.inner_cone.cos(),
            outer_cos: self.outer_cone.cos(),
            shadow_map: NO_SHADOW_MAP,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

/// `GpuLight::shadow_map` of a light without a shadow map (`core::shading::shadow`).
pub const NO_SHADOW_MAP: u32 = u32::MAX;

/// `Light` in shaders/shared/surface.wgsl (viewer frame). 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    pub position: [f32; 3],
    pub kind: u32,
    pub direction: [f32; 3],
    /// 0: unlimited.
    pub range: f32,
    pub color: [f32; 3],
    pub inner_cos: f32,
    pub outer_cos: f32,
    /// Its shadow map's index in the frame's maps (`core::shading::shadow`), or `NO_SHADOW_MAP`.
    pub shadow_map: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// How surfaces are lit (`--lighting`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightingMode {
    /// The scene's own lights with the glTF BRDF where it has some, else the headlight.
    #[default]
    Auto,
    /// A light at the viewer, Lambert on the base colour (the paper's look; the fast pipelines).
    Headlight,
    /// The glTF metallic-roughness BRDF with the scene's lights (none: only emission and
    /// the ambient term).
    Pbr,
}

crate::choices!(LightingMode {
    Auto => ("auto", "The scene's own lights with the glTF BRDF where it has some, else the headlight"),
    Headlight => ("headlight", "A light at the viewer, Lambert on the base colour (the paper's look)"),
    Pbr => ("pbr", "The glTF metallic-roughness BRDF with the scene's lights"),
});

/// The tone mapping of the linear colour (`--tonemap`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tonemap {
    /// Khronos PBR Neutral: colours below 0.76 untouched, highlights compressed towards white.
    #[default]
    PbrNeutral,
    /// The ACES filmic curve (Narkowicz's fit).
    Aces,
    /// Clamp to 0..1.
    None,
    /// No tone mapping and no clamp: the linear colour × 2^EV, for a float colour target
    /// (`--hdr`; not a `--tonemap` value).
    Linear,
}

crate::choices!(Tonemap {
    PbrNeutral => ("pbr-neutral", "Khronos PBR Neutral: highlights compressed towards white"),
    Aces => ("aces", "The ACES filmic curve"),
    None => ("none", "Clamp to 0..1"),
});

impl Tonemap {
    /// `TONEMAP_*` in the WGSL `constants` module.
    pub fn code(self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::PbrNeutral => 1,
            Tonemap::Aces => 2,
            Tonemap::Linear => 3,
        }
    }
}

/// `Lighting` in shaders/shared/surface_bindings.wgsl (a uniform): the frame's lighting. 336 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightingParams {
    /// Lights in use (the buffer holds at least one entry).
    pub count: u32,
    /// 0: headlight, 1: the glTF BRDF (`LIGHTING_*`).
    pub pbr: u32,
    /// 2^EV (`--exposure`).
    pub exposure: f32,
    /// `TONEMAP_*`.
    pub tonemap: u32,
    /// 1: image-based lighting from the environment (`core::shading::environment`) replaces the ambient term.
    pub environment: u32,
    /// 1: background pixels show the environment (one the user gave).
    pub env_background: u32,
    /// First texel of the split-sum table in the environment buffer.
    pub env_lut: u32,
    /// 1: the scene's lights cast shadows (the ray tracer's shadow rays; `--no-shadows`: 0).
    pub shadows: u32,
    /// The most probes a texture sample takes along its footprint's longer axis
    /// (`ShadingSettings::anisotropy`; 0 or 1: isotropic).
    pub anisotropy: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
    /// Viewer frame → environment (scene) frame: the columns of the rotation (w unused).
    pub env_rotation: [[f32; 4]; 3],
    /// E(n)/π as spherical-harmonic coefficients (rgb, w unused).
    pub env_sh: [[f32; 4]; 9],
    /// The prefiltered levels: first texel, width, height, unused.
    pub env_levels: [[u32; 4]; ENV_LEVELS],
}

/// What a scene brings to a frame's lighting: its number of lights, and whether its materials
/// are physically based (a glTF file's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneLighting {
    pub lights: usize,
    pub physically_based: bool,
}

impl LightingParams {
    /// The frame's lighting for a scene with `lights` lights and perhaps an environment: the
    /// glTF BRDF with `LightingMode::Pbr`, or with `Auto` where the scene is physically based
    /// (a glTF file: its emission and factors are the BRDF's, with or without lights and an
    /// environment) or has lights or an environment; 2^EV; the tone mapping.
    pub fn of(
        mode: LightingMode,
        scene: SceneLighting,
        environment: Option<&PreparedEnvironment>,
        exposure_ev: f32,
        tonemap: Tonemap,
    ) -> LightingParams {
        let lights = scene.lights;
        let pbr = match mode {
            LightingMode::Auto => scene.physically_based || lights > 0 || environment.is_some(),
            LightingMode::Headlight => false,
            LightingMode::Pbr => true,
        };
        let mut params = LightingParams {
            count: lights as u32,
            pbr: pbr as u32,
            exposure: exposure_ev.exp2(),
            tonemap: tonemap.code(),
            ..Default::default()
        };
        if let (Some(env), true) = (environment, pbr) {
            params.environment = 1;
            params.env_background = env.background as u32;
            params.env_lut = env.lut_offset;
            params.env_sh = env.sh.map(|c| c.extend(0.0).to_array());
            params.env_levels = env.levels.map(|[o, w, h]| [o, w, h, 0]);
            params.env_rotation = [Vec3::X, Vec3::Y, Vec3::Z].map(|c| c.extend(0.0).to_array());
        }
        params
    }

    /// With the viewer frame → environment frame rotation: back through `view` (scene →
    /// viewer) to the scene, then the environment turned by `environment_yaw_deg` about +y (what
    /// the map shows at azimuth θ appears at θ + yaw).
    pub fn with_view(mut self, view: Mat4, environment_yaw_deg: f32) -> LightingParams {
        let turn = glam::Mat3::from_rotation_y(environment_yaw_deg.to_radians());
        let m = turn * glam::Mat3::from_mat4(view).transpose();
        self.env_rotation = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.extend(0.0).to_array());
        self
    }
}

/// The lights as the fragment stage reads them, in the viewer frame (`view`: scene → viewer),
/// at least one entry (a buffer cannot be empty; `LightingParams::count` says how many count).
pub fn gpu_lights(lights: &[Light], view: Mat4) -> Vec<GpuLight> {
    let mut out: Vec<GpuLight> = lights.iter().map(|l| l.transformed(view).gpu()).collect();
    if out.is_empty() {
        out.push(GpuLight::default());
    }
    out
}

/// Khronos PBR Neutral tone mapping (https://github.com/KhronosGroup/ToneMapping, `pbr_neutral`
/// in surface.wgsl).
pub fn pbr_neutral(c: Vec3) -> Vec3 {
    const START: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = c.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c - offset;
    let peak = c.max_element();
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    let c = c * (new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.lerp(Vec3::splat(new_peak), g)
}

/// The ACES filmic curve, Narkowicz's fit (`aces` in surface.wgsl).
pub fn aces(c: Vec3) -> Vec3 {
    let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((c * (a * c + b)) / (c * (cc * c + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// The tone mapped colour, 0..1 (`tonemap` in surface.wgsl).
pub fn tonemap(c: Vec3, params: &LightingParams) -> Vec3 {
    let c = (c * params.exposure).max(Vec3::ZERO);
    match params.tonemap {
        1 => pbr_neutral(c),
        2 => aces(c),
        3 => return c,
        _ => c,
    }
    .clamp(Vec3::ZERO, Vec3::ONE)
}
