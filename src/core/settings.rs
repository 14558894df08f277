//! Render settings, in four groups: where the viewer stands and what the panorama is
//! ([`ViewSettings`]), how triangles are subdivided ([`SubdivisionSettings`], seed 002 §2.3),
//! how surfaces are shaded ([`ShadingSettings`]) and what is measured ([`MeasureSettings`],
//! seed 002 §4). Builders (`with_*`) set one field of a group.

use glam::{Mat4, Vec3};

use crate::core::panoramas::panorama::EyeModel;
use crate::core::panoramas::projection::{Projection, Vertical};
use crate::error::{Error, Result};

/// Default memory budget for the subdivision buffers, MiB.
pub const DEFAULT_MEMORY_MB: u32 = 256;
/// Largest N for `fixed:N` (its N² triangles are made by one GPU thread).
pub const MAX_FIXED: u32 = 64;
/// Default L in pixels: see the README for the error it gives.
pub const DEFAULT_EDGE_PX: f32 = 32.0;
/// Default N_max, as in the paper.
pub const DEFAULT_MAX_DIV: u32 = 7;
/// Default τ of the error split, pixels: see the README for the error it gives.
pub const DEFAULT_MAX_ERROR_PX: f32 = 0.4;
/// `--reflect-max`: seed 000's Reflect_max.
pub const DEFAULT_REFLECT_MAX: u32 = 3;
/// The deepest `--reflect-max` (the ray tracer's stack of pending rays is this deep + 1).
pub const MAX_REFLECT: u32 = 8;

/// How triangles are drawn (`--method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
/// How triangles are split (`--method`).
pub enum Method {
    /// No split: every vertex at its projected place, straight edges (the paper's "Vert").
    Vertex,
    /// Every edge split into N, regular N² lattice (the paper's fixed comparison; ignores N_max).
    /// Beyond 32 divisions the triangle is first cut into K² pieces of N/K (K = ceil(N/32)).
    Fixed(u32),
    /// Each edge split into as many equal parts as its rule asks (see [`Split`]), with pre-split
    /// beyond N_max.
    Adaptive(Split),
    /// The conventional slit-mosaic renderer with slits of W columns (no subdivision).
    Slit(u32),
    /// Ray tracing (seed 000): one primary ray per pixel from its eye point, the closest hit
    /// through a BVH; exact per pixel (the cylinder's `exact` vertical model, or the sphere).
    Trace,
}

/// What decides an adaptive edge's divisions (`--split`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Split {
    /// Its projected error (τ = --max-error-px): N = ceil(S·√(b / 8τ)), b the largest second
    /// difference of the projected edge sampled at S = 8 segments (`Subdivider::edge_profile`);
    /// edges stay under 8·L long, and the length rule holds near the eye circle.
    #[default]
    Error,
    /// Its projected length (L = --edge-px), N = ceil(l/L): the paper's eq. 5.
    Length,
}

crate::choices!(Split {
    Error => ("error", "Each edge's divisions from its projected error (τ)"),
    Length => ("length", "Each edge's divisions from its projected length (L, the paper's eq. 5)"),
});

/// The subdivision rule as the `subdivide` stage reads it (`SubdivideParams::method`); the WGSL
/// constants `METHOD_VERTEX`, `METHOD_FIXED`, `METHOD_ADAPTIVE` are generated from it.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitRule {
    Vertex = 0,
    Fixed = 1,
    Adaptive = 2,
    AdaptiveError = 3,
}

impl SplitRule {
    pub const ALL: [SplitRule; 4] =
        [SplitRule::Vertex, SplitRule::Fixed, SplitRule::Adaptive, SplitRule::AdaptiveError];
    /// Whether `SubdivideParams::method` is one of the adaptive rules (pre-split, diamonds).
    pub fn is_adaptive(method: u32) -> bool {
        method == SplitRule::Adaptive as u32 || method == SplitRule::AdaptiveError as u32
    }
    /// Whether `SubdivideParams::method` spaces nodes by azimuth and draws them with w = r (the
    /// error split: `cpu::subdivide::spacing`).
    pub fn spaces_by_azimuth(method: u32) -> bool {
        method == SplitRule::AdaptiveError as u32
    }
    /// The WGSL constant's name.
    pub fn wgsl_name(self) -> &'static str {
        match self {
            SplitRule::Vertex => "METHOD_VERTEX",
            SplitRule::Fixed => "METHOD_FIXED",
            SplitRule::Adaptive => "METHOD_ADAPTIVE",
            SplitRule::AdaptiveError => "METHOD_ERROR",
        }
    }
}

impl Method {
    /// The `subdivide` stage's rule and its fixed N (the slit renderer does not subdivide).
    pub fn split_rule(self) -> (SplitRule, u32) {
        match self {
            Method::Vertex | Method::Slit(_) | Method::Trace => (SplitRule::Vertex, 1),
            Method::Fixed(n) => (SplitRule::Fixed, n),
            Method::Adaptive(Split::Length) => (SplitRule::Adaptive, 0),
            Method::Adaptive(Split::Error) => (SplitRule::AdaptiveError, 0),
        }
    }

    /// Parses `adaptive` (the error split), `adaptive:length` (eq. 5), `adaptive:error`,
    /// `vertex`, `fixed:N`, `slit:W` or `trace` (the parser of `--method`).
    pub fn parse(s: &str) -> std::result::Result<Method, String> {
        match s {
            "vertex" => Ok(Method::Vertex),
            "trace" => Ok(Method::Trace),
            "adaptive" | "adaptive:error" => Ok(Method::Adaptive(Split::Error)),
            "adaptive:length" => Ok(Method::Adaptive(Split::Length)),
            _ => match (s.strip_prefix("fixed:").map(str::parse::<u32>), s.strip_prefix("slit:").map(str::parse::<u32>)) {
                (Some(Ok(n)), _) if (1..=MAX_FIXED).contains(&n) => Ok(Method::Fixed(n)),
                (_, Some(Ok(w))) if w >= 1 => Ok(Method::Slit(w)),
                _ => Err(format!(
                    "unknown method '{s}': expected adaptive, adaptive:length, vertex, fixed:N with N in 1..={MAX_FIXED}, slit:W with W ≥ 1 columns, or trace"
                )),
            },
        }
    }

    pub fn name(self) -> String {
        match self {
            Method::Vertex => "vertex".into(),
            Method::Fixed(n) => format!("fixed:{n}"),
            Method::Adaptive(Split::Error) => "adaptive".into(),
            Method::Adaptive(Split::Length) => "adaptive:length".into(),
            Method::Slit(w) => format!("slit:{w}"),
            Method::Trace => "trace".into(),
        }
    }
}

/// Where the viewer stands and what the panorama is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    pub projection: Projection,
    /// Viewer position in scene coordinates.
    pub viewer: Vec3,
    /// Turn of the view about +y in degrees; positive turns left (counter-clockwise from above).
    pub yaw_deg: f32,
}

/// How triangles are subdivided, and the memory the subdivision may use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubdivisionSettings {
    pub method: Method,
    /// L: the longest projected edge wanted from `adaptive:length`, pixels (the error split
    /// keeps edges under 8·L, and L near the eye circle).
    pub edge_px: f32,
    /// τ: the display-position error the error split allows an edge, pixels.
    pub max_error_px: f32,
    /// N_max: the largest lattice step of one piece.
    pub max_div: u32,
    /// Budget for the piece and output buffers, MiB.
    pub memory_mb: u32,
}

/// How surfaces are shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingSettings {
    /// Background colour, display values, each channel in [0, 1].
    pub background: [f32; 3],
    /// Ambient term of the headlight shading.
    pub ambient: f32,
    /// The ray tracer's depth of mirror and refraction rays (`--reflect-max`, seed 000's
    /// Reflect_max): each hit on a mirroring or transmitting surface spawns up to two rays, at
    /// most this many bounces deep (up to 2^(n+1) − 2 secondary rays per pixel).
    pub reflect_max: u32,
    /// The ray tracer's point light (`--light`, scene coordinates), with hard shadows; None:
    /// the headlight at the viewer, as the rasterizer.
    pub light: Option<Vec3>,
    /// The ray tracer's visual-field level of detail (seed 000, `--lod visual-field` with
    /// `--method trace`): the gaze; each primary ray's level (eq. 8) sets its bounces (eq. 9),
    /// and rays outside the visual field are not traced.
    pub trace_gaze: Option<crate::core::detail::visual_field::Gaze>,
    /// With `trace_gaze`: N_min / N_max of eq. 10, the share of an object's triangles that a ray
    /// at level 0 meets (`--lod-p3`); the scene's BVH holds each object's chain down to it.
    pub trace_min_share: f32,
    /// How surfaces are lit (`--lighting`): the glTF BRDF under the scene's lights, or the
    /// headlight.
    pub lighting: crate::core::shading::light::LightingMode,
    /// Exposure in stops (`--exposure`): the linear colour is scaled by 2^EV before tone mapping
    /// (the glTF BRDF only).
    pub exposure_ev: f32,
    /// Tone mapping of the lit colour (`--tonemap`; the glTF BRDF only).
    pub tonemap: crate::core::shading::light::Tonemap,
    /// Whether the scene's lights cast shadows (`--no-shadows`: false): by shadow maps in the
    /// drawing stages (directional and spot lights, `core::shading::shadow`), by rays in the ray tracer.
    pub shadows: bool,
    /// The side of a shadow map in texels (`--shadow-map-size`, a multiple of 64).
    pub shadow_map_size: u32,
    /// The environment turned about the vertical axis, degrees (`--environment-yaw`).
    pub environment_yaw_deg: f32,
    /// Also draw the linear colour × 2^EV in floats, not tone mapped, beside the display colour
    /// of the same frame (`--hdr`: [`Frame::hdr`](crate::core::frame::Frame::hdr); the
    /// projection methods only).
    pub hdr: bool,
    /// Samples per pixel of the display colour (`--samples`: 1, 2, 4, 8, 16 or 32): each pixel
    /// shows the average of its samples' tone-mapped linear colours (the projection methods and
    /// slits multisample, resolved in linear light; the ray tracer traces a ray through each of
    /// [`sample_position`](crate::core::shading::sampling::sample_position)). The other outputs (the error
    /// pass's targets, depth, the linear HDR colour) stay one sample at the pixel's centre.
    pub samples: u32,
    /// The most probes a texture sample takes along its footprint's longer axis (`--anisotropy`,
    /// 1..=16; 1: isotropic, the longest axis picks the mip level): anisotropic filtering, in the
    /// drawing stages (the footprint from the screen derivatives) and the ray tracer (the ray
    /// cone's ellipse on the surface).
    pub anisotropy: u32,
}

/// The most probes `--anisotropy` takes (the usual hardware limit; twister filters by hand, so
/// every adapter has it).
pub const MAX_ANISOTROPY: u32 = 16;

/// The sample counts `--samples` takes.
pub const SAMPLE_COUNTS: [u32; 6] = [1, 2, 4, 8, 16, 32];

/// What a render measures besides drawing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeasureSettings {
    /// Measure the longest visible output edge (`FrameStats::max_sub_edge_px`); costs a few
    /// projections per output triangle.
    pub edges: bool,
    /// Run the error pass: every fragment also writes its display-position error and object
    /// id, reduced to statistics on the GPU (slower; off for plain rendering and speed runs).
    pub error: bool,
    /// The error pass measures the display-position error as the angle between where a point
    /// was drawn and where it belongs (arcminutes, seen from the centre) instead of in pixels:
    /// on the sphere, pixels shrink towards the poles.
    pub error_angle: bool,
    /// Also read back each pixel's distance from its eye point along its ray (`Frame::depth`).
    pub depth: bool,
    /// Time each of the subdivision's passes apart (`FrameStats::ms_subdivide_passes` by entry
    /// point, where the adapter has timestamps) rather than in three groups: a pass boundary and
    /// a pair of timestamps each, which cost the software driver ~0.3–0.5 ms apiece (benchmarks:
    /// `bench speed --pass-times`).
    pub pass_times: bool,
    /// Also read back the surface point each pixel shows (`Frame::positions`), for the
    /// display-position error against the ray tracer (`error --against trace`).
    pub positions: bool,
    /// Test hook: draws everything shifted by this many pixels (x right, y down) while the
    /// error pass measures against the true projection.
    #[doc(hidden)]
    pub shift_px: [f32; 2],
    /// Test hook: the error reduction binds one eye at a time even where both would fit (as it
    /// must for images beyond one storage binding, e.g. 8192×4096 per eye on lavapipe).
    #[doc(hidden)]
    pub reduce_per_eye: bool,
}

impl MeasureSettings {
    /// Whether the drawing stages write the measuring targets (error, object id, distance).
    pub fn targets(&self) -> bool {
        self.error || self.depth || self.positions
    }

    /// The colour attachments the drawing stages write: colour; + error, object, distance when
    /// measuring; + positions.
    pub fn outputs(&self) -> usize {
        if self.positions {
            5
        } else if self.targets() {
            4
        } else {
            1
        }
    }
}

/// The largest `--shadow-map-size` (a map of 8192² texels holds 256 MiB of depths).
pub const MAX_SHADOW_MAP_SIZE: u32 = 8192;

impl RenderSettings {
    /// Whether a frame lit by the glTF BRDF (`pbr`) of a scene with `lights` has shadow maps:
    /// shadows on, a drawing method (the ray tracer shadows by rays), and a light (the drawing
    /// pipelines' `SHADOW_MAPS`).
    pub fn uses_shadow_maps(&self, lights: &[crate::core::shading::light::Light], pbr: bool) -> bool {
        pbr && self.shading.shadows && self.subdivision.method != Method::Trace && !lights.is_empty()
    }

    /// A frame's lights (viewer frame, each with its shadow map's index), lighting and shadow
    /// maps, for a scene with `lights`, perhaps an environment, and the bounding box `bounds`
    /// (scene frame; the maps are fitted to it).
    pub fn shadowed_lighting(
        &self,
        lights: &[crate::core::shading::light::Light],
        physically_based: bool,
        environment: Option<&crate::core::shading::environment::PreparedEnvironment>,
        bounds: Option<(Vec3, Vec3)>,
    ) -> (
        Vec<crate::core::shading::light::GpuLight>,
        crate::core::shading::light::LightingParams,
        Vec<crate::core::shading::shadow::GpuShadowMap>,
    ) {
        let (mut gpu_lights, params) = self.lighting(lights, physically_based, environment);
        let maps = match bounds {
            Some((min, max)) if self.uses_shadow_maps(lights, params.pbr != 0) => {
                let corners = crate::core::shading::shadow::box_corners(min, max, self.view());
                crate::core::shading::shadow::plan_shadow_maps(
                    &mut gpu_lights,
                    lights.len(),
                    &corners,
                    self.shading.shadow_map_size,
                )
            }
            _ => Vec::new(),
        };
        (gpu_lights, params, maps)
    }

    /// A frame's lights as the fragment stage reads them (viewer frame of this view) and its
    /// lighting, for a scene with `lights`, physically based or not (group 1's last two
    /// bindings; the CPU twins' `MaterialTable::with_lighting`).
    pub fn lighting(
        &self,
        lights: &[crate::core::shading::light::Light],
        physically_based: bool,
        environment: Option<&crate::core::shading::environment::PreparedEnvironment>,
    ) -> (Vec<crate::core::shading::light::GpuLight>, crate::core::shading::light::LightingParams) {
        let scene = crate::core::shading::light::SceneLighting { lights: lights.len(), physically_based };
        (
            crate::core::shading::light::gpu_lights(lights, self.view()),
            self.lighting_params(scene, environment).with_view(self.view(), self.shading.environment_yaw_deg),
        )
    }

    /// The frame's lighting for a scene with what it brings (`scene`) and perhaps an environment.
    pub fn lighting_params(
        &self,
        scene: crate::core::shading::light::SceneLighting,
        environment: Option<&crate::core::shading::environment::PreparedEnvironment>,
    ) -> crate::core::shading::light::LightingParams {
        let s = &self.shading;
        let tonemap = s.tonemap;
        crate::core::shading::light::LightingParams {
            shadows: s.shadows as u32,
            anisotropy: s.anisotropy,
            ..crate::core::shading::light::LightingParams::of(s.lighting, scene, environment, s.exposure_ev, tonemap)
        }
    }
}

/// Everything a render needs besides the scene.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct RenderSettings {
    pub view: ViewSettings,
    pub subdivision: SubdivisionSettings,
    pub shading: ShadingSettings,
    pub measure: MeasureSettings,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings { projection: Projection::default(), viewer: Vec3::ZERO, yaw_deg: 0.0 }
    }
}

impl Default for SubdivisionSettings {
    fn default() -> Self {
        SubdivisionSettings {
            method: Method::Adaptive(Split::Error),
            edge_px: DEFAULT_EDGE_PX,
            max_error_px: DEFAULT_MAX_ERROR_PX,
            max_div: DEFAULT_MAX_DIV,
            memory_mb: DEFAULT_MEMORY_MB,
        }
    }
}

impl Default for ShadingSettings {
    fn default() -> Self {
        ShadingSettings {
            background: [0.1, 0.1, 0.12],
            ambient: 0.3,
            reflect_max: DEFAULT_REFLECT_MAX,
            light: None,
            trace_gaze: None,
            trace_min_share: crate::core::detail::lod::LodParams::DEFAULT.p3,
            lighting: Default::default(),
            exposure_ev: 0.0,
            tonemap: Default::default(),
            hdr: false,
            samples: 1,
            anisotropy: 1,
            shadows: true,
            shadow_map_size: crate::core::shading::shadow::DEFAULT_SHADOW_MAP_SIZE,
            environment_yaw_deg: 0.0,
        }
    }
}

macro_rules! builders {
    ($($name:ident: $ty:ty => $group:ident.$field:ident),* $(,)?) => {
        impl RenderSettings {
            $(
                #[doc = concat!("These settings with `", stringify!($group), ".", stringify!($field), "` set.")]
                pub fn $name(mut self, value: $ty) -> Self {
                    self.$group.$field = value;
                    self
                }
            )*
        }
    };
}

builders! {
    with_projection: Projection => view.projection,
    with_viewer: Vec3 => view.viewer,
    with_yaw_deg: f32 => view.yaw_deg,
    with_method: Method => subdivision.method,
    with_edge_px: f32 => subdivision.edge_px,
    with_max_error_px: f32 => subdivision.max_error_px,
    with_max_div: u32 => subdivision.max_div,
    with_memory_mb: u32 => subdivision.memory_mb,
    with_background: [f32; 3] => shading.background,
    with_ambient: f32 => shading.ambient,
    with_reflect_max: u32 => shading.reflect_max,
    with_light: Option<Vec3> => shading.light,
    with_trace_gaze: Option<crate::core::detail::visual_field::Gaze> => shading.trace_gaze,
    with_trace_min_share: f32 => shading.trace_min_share,
    with_lighting: crate::core::shading::light::LightingMode => shading.lighting,
    with_exposure_ev: f32 => shading.exposure_ev,
    with_tonemap: crate::core::shading::light::Tonemap => shading.tonemap,
    with_hdr: bool => shading.hdr,
    with_samples: u32 => shading.samples,
    with_anisotropy: u32 => shading.anisotropy,
    with_shadows: bool => shading.shadows,
    with_shadow_map_size: u32 => shading.shadow_map_size,
    with_environment_yaw_deg: f32 => shading.environment_yaw_deg,
    with_measure_edges: bool => measure.edges,
    with_pass_times: bool => measure.pass_times,
    with_measure_error: bool => measure.error,
    with_error_angle: bool => measure.error_angle,
    with_depth: bool => measure.depth,
    with_positions: bool => measure.positions,
    with_shift_px: [f32; 2] => measure.shift_px,
    with_reduce_per_eye: bool => measure.reduce_per_eye,
}

impl RenderSettings {
    /// The default settings for a projection.
    pub fn new(projection: Projection) -> Self {
        RenderSettings::default().with_projection(projection)
    }

    pub fn projection(&self) -> &Projection {
        &self.view.projection
    }

    /// World → viewer frame: translate the viewer to the origin, then undo the yaw.
    pub fn view(&self) -> Mat4 {
        let display =
            Mat4::from_rotation_y(-self.view.yaw_deg.to_radians()) * Mat4::from_translation(-self.view.viewer);
        // A tracked head: the frame drawn is the head's (`core::panoramas::head`).
        match &self.view.projection.head {
            Some(head) => head.to_head() * display,
            None => display,
        }
    }

    pub fn validate(&self) -> Result<()> {
        self.view.projection.validate()?;
        self.validate_view()?;
        self.validate_subdivision()?;
        self.validate_method()?;
        self.validate_shading()?;
        if self.subdivision.memory_mb < 8 {
            return Err(Error::setting(
                "subdivision.memory_mb",
                format!("must be at least 8, got {}", self.subdivision.memory_mb),
            ));
        }
        Ok(())
    }

    /// The viewer's place and turn: [`Self::validate`]'s first part.
    fn validate_view(&self) -> Result<()> {
        let max = crate::core::scenes::scene::MAX_COORDINATE;
        if !self.view.viewer.is_finite() || self.view.viewer.abs().max_element() > max {
            return Err(Error::setting("view.viewer", format!("must lie within ±{max:e}, got {}", self.view.viewer)));
        }
        if !self.view.yaw_deg.is_finite() {
            return Err(Error::setting("view.yaw_deg", "must be a finite number of degrees"));
        }
        Ok(())
    }

    /// The subdivision's numbers (L, τ, N_max): part of [`Self::validate`].
    fn validate_subdivision(&self) -> Result<()> {
        let s = &self.subdivision;
        if !(s.edge_px.is_finite() && s.edge_px >= 0.25) {
            return Err(Error::setting(
                "subdivision.edge_px",
                format!("must be a number of pixels ≥ 0.25, got {}", s.edge_px),
            ));
        }
        if !(s.max_error_px.is_finite() && s.max_error_px >= 0.01) {
            return Err(Error::setting(
                "subdivision.max_error_px",
                format!("must be a number of pixels ≥ 0.01, got {}", s.max_error_px),
            ));
        }
        if !(1..=64).contains(&s.max_div) {
            return Err(Error::setting("subdivision.max_div", format!("must be between 1 and 64, got {}", s.max_div)));
        }
        Ok(())
    }

    /// The method against the panorama, the vertical model and the outputs: part of
    /// [`Self::validate`].
    fn validate_method(&self) -> Result<()> {
        let s = &self.subdivision;
        if let Method::Slit(w) = s.method {
            let model = self.view.projection.model();
            if model.drawn_as_pinhole() {
                return Err(Error::setting(
                    "subdivision.method",
                    format!("slit:{w}: a CAVE wall is one perspective per eye, which every method draws exactly: use vertex, or trace as the reference"),
                ));
            }
            if self.view.projection.head.is_some() {
                return Err(Error::setting(
                    "subdivision.method",
                    format!("slit:{w} pastes the slits of eyes on the circle about the display's centre; a tracked head has fixed eyes: use trace as the reference"),
                ));
            }
            let panorama = self.view.projection.panorama;
            if !model.has_slits() {
                return Err(Error::setting(
                    "subdivision.method",
                    format!(
                        "slit:{w} pastes the cylinder's, the sphere's and VR180's slits; the {} has none yet: use trace as the reference",
                        panorama.name()
                    ),
                ));
            }
            if w > self.view.projection.width {
                return Err(Error::setting(
                    "subdivision.method",
                    format!("slit:{w} is wider than the image ({} columns)", self.view.projection.width),
                ));
            }
        }
        if matches!(s.method, Method::Vertex | Method::Fixed(_))
            && !self.view.projection.model().takes_unmeasured_edges()
        {
            return Err(Error::setting(
                "subdivision.method",
                format!(
                    "{}: the fisheye bends an edge beyond its rim round the circle, and an edge split without \
                     measuring it is drawn as chords that cut into the circle (holes in a closed room): use adaptive \
                     or adaptive:length",
                    s.method.name()
                ),
            ));
        }
        self.validate_tilted_dome()?;
        if s.method == Method::Trace
            && self.view.projection.model().eye_model() == EyeModel::Circle
            && self.view.projection.vertical == Vertical::Paper
        {
            return Err(Error::setting(
                "view.projection.vertical",
                "trace follows each pixel's ray, and the paper's vertical model (v = R_T·y/r) has none \
                 (the points it shows at a pixel lie on a curve): use the exact model",
            ));
        }
        if self.shading.hdr && matches!(s.method, Method::Slit(_) | Method::Trace) {
            return Err(Error::setting(
                "shading.hdr",
                "the linear colour comes from the projection methods (vertex, fixed, adaptive); slit and trace write display colours",
            ));
        }
        Ok(())
    }

    /// A tilted fisheye's chords against the room its dropped cone leaves: part of
    /// [`Self::validate`].
    fn validate_tilted_dome(&self) -> Result<()> {
        let (s, projection) = (&self.subdivision, &self.view.projection);
        if let Method::Adaptive(split) = s.method {
            let error_split = split == Split::Error;
            let dip = projection.chord_dip_px(error_split, s.edge_px, s.max_error_px);
            if projection.dome_tilt != 0.0 && dip > 0.0 && projection.dome_antipode_cone(dip).is_none() {
                let room = projection.max_chord_dip_px();
                let (field, most) = if error_split {
                    ("subdivision.max_error_px", format!("{:.2} px", room / 4.0))
                } else {
                    (
                        "subdivision.edge_px",
                        format!("{:.1} px", (8.0 * 0.5 * projection.width as f32 * room).sqrt() / 1.5),
                    )
                };
                return Err(Error::setting(
                    field,
                    format!(
                        "a {}° fisheye tilted {}° at {} px takes at most {most}: beyond that, its chords beyond the rim dip \
                         into the circle, and the point opposite its axis leaves no room to drop them",
                        projection.fov, projection.dome_tilt, projection.width
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The shading's part of [`Self::validate`].
    fn validate_shading(&self) -> Result<()> {
        let samples = self.shading.samples;
        if !SAMPLE_COUNTS.contains(&samples) {
            return Err(Error::setting("shading.samples", format!("must be 1, 2, 4, 8, 16 or 32, got {samples}")));
        }
        if !(1..=MAX_ANISOTROPY).contains(&self.shading.anisotropy) {
            return Err(Error::setting(
                "shading.anisotropy",
                format!("must be 1 to {MAX_ANISOTROPY} probes, got {}", self.shading.anisotropy),
            ));
        }
        if !(self.shading.exposure_ev.is_finite() && self.shading.exposure_ev.abs() <= 64.0) {
            return Err(Error::setting(
                "shading.exposure_ev",
                format!("must be a number of stops between −64 and 64, got {}", self.shading.exposure_ev),
            ));
        }
        if !(self.shading.environment_yaw_deg.is_finite() && self.shading.environment_yaw_deg.abs() <= 3600.0) {
            return Err(Error::setting(
                "shading.environment_yaw_deg",
                format!("must be a number of degrees between −3600 and 3600, got {}", self.shading.environment_yaw_deg),
            ));
        }
        if self.shading.reflect_max > MAX_REFLECT {
            return Err(Error::setting(
                "shading.reflect_max",
                format!("must be between 0 and {MAX_REFLECT}, got {}", self.shading.reflect_max),
            ));
        }
        if let Some(light) = self.shading.light {
            let max = crate::core::scenes::scene::MAX_COORDINATE;
            if !light.is_finite() || light.abs().max_element() > max {
                return Err(Error::setting("shading.light", format!("must lie within ±{max:e}, got {light}")));
            }
        }
        let size = self.shading.shadow_map_size;
        if !(64..=MAX_SHADOW_MAP_SIZE).contains(&size) || size % 64 != 0 {
            return Err(Error::setting(
                "shading.shadow_map_size",
                format!("must be a multiple of 64 between 64 and {MAX_SHADOW_MAP_SIZE}, got {size}"),
            ));
        }
        Ok(())
    }
}
