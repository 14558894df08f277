//! Options shared by the commands that render: the view (projection, viewer, method) and the
//! level of detail, with their parsers and checks.

use std::path::PathBuf;

use crate::choice::choice;
use clap::Args;
use glam::Vec3;
use twister::core::shading::environment::PreparedEnvironment;
use twister::core::shading::light::{LightingMode, Tonemap};

use twister::core::detail::lod::LodParams;
use twister::core::detail::visual_field::Gaze;
use twister::core::panoramas::head::Head;
use twister::core::panoramas::projection::{PanoramaKind, DEFAULT_POLE_MERGE};
use twister::core::settings::{
    Method, Split, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, DEFAULT_MAX_ERROR_PX, DEFAULT_MEMORY_MB, DEFAULT_REFLECT_MAX,
};
use twister::error::{Error, Result};
use twister::output::{ImageFormat, Layout};
use twister::{Projection, RenderSettings, Vertical};

#[derive(Args, Clone)]
pub struct ViewArgs {
    /// The panorama: cylinder (the TWISTER display), equirect (the full sphere, 360° × 180°
    /// per eye: omni-directional stereo as VR players, 360° video and Blender use), vr180
    /// (its front half, 180° × 180° per eye), fisheye (the fulldome master: W × W,
    /// equidistant, the zenith at the centre and the front at the bottom; --fov, --dome-tilt;
    /// mono with --eye-radius 0), cubemap (six 90° faces per eye in YouTube's 3×2 grid: right,
    /// left, up / down, front, back) or cave (CAVE walls: --cave, --head). [default: cylinder;
    /// equirect with --preset]
    #[arg(help_heading = "Panorama", long, value_parser = choice::<PanoramaKind>())]
    pub panorama: Option<PanoramaKind>,
    /// Image width per eye in pixels (the full 360°; vr180: 180°; fisheye: --fov; cubemap: three
    /// faces) [default: 3168; equirect, vr180 and fisheye 4096; cubemap 3072].
    #[arg(help_heading = "Panorama", long)]
    pub width: Option<u32>,
    /// Image height per eye in pixels [default: 600; equirect: width/2; vr180, fisheye: width;
    /// cubemap: 2·width/3].
    #[arg(help_heading = "Panorama", long)]
    pub height: Option<u32>,
    /// Size preset of the full sphere (implies --panorama equirect): vr4k (4096×4096 top-bottom:
    /// 4096×2048 per eye), vr6k (6144×6144), vr8k (8192×8192), vr16k (16384×16384: drawn in
    /// tiles where the adapter's textures are smaller, written as rows arrive).
    #[arg(help_heading = "Panorama", long, value_enum, conflicts_with_all = ["width", "height"])]
    pub preset: Option<Preset>,
    /// equirect: parallel (every eye ray tangent to the eye circle, Google ODS, Cycles
    /// "parallel"), or DIST: the rays converge on the sphere of DIST metres (Cycles "off-axis")
    /// [default: parallel].
    #[arg(help_heading = "Panorama", long, value_parser = parse_convergence)]
    pub convergence: Option<Convergence>,
    /// equirect: FROM,TO degrees of altitude over which the eye offset fades to 0 towards the
    /// poles (Blender's pole merge), or off [default: 60,75].
    #[arg(help_heading = "Panorama", long, value_parser = parse_pole_merge)]
    pub pole_merge: Option<PoleMerge>,
    /// fisheye: the field of view inscribed in the square image, degrees, 0 < FOV ≤ 360
    /// [default: 180].
    #[arg(help_heading = "Panorama", long, allow_hyphen_values = true)]
    pub fov: Option<f32>,
    /// fisheye: the dome's front raised by DEG degrees (a tilted dome), -90..90 [default: 0].
    #[arg(help_heading = "Panorama", long, value_name = "DEG", allow_hyphen_values = true)]
    pub dome_tilt: Option<f32>,
    /// R_T: radius of the display cylinder, metres.
    #[arg(help_heading = "Eyes and display", long, default_value_t = 1.0)]
    pub screen_radius: f32,
    /// d_e: radius of the circle the eyes move on, metres.
    #[arg(help_heading = "Eyes and display", long, default_value_t = 0.032)]
    pub eye_radius: f32,
    /// Vertical model: paper (v = R_T·y/r) or exact (pinhole on the eye circle) [default: paper;
    /// exact when `trace` draws the cylinder, since the paper's model has no ray per pixel].
    #[arg(help_heading = "Eyes and display", long, value_parser = choice::<Vertical>())]
    pub vertical: Option<Vertical>,
    /// Viewer: a position x,y,z in scene units, or camera[:N] for the file's N-th camera (default 0;
    /// its position and yaw, plus --yaw).
    #[arg(help_heading = "Scene and placement", long, value_parser = parse_viewer, default_value = "0,0,0", allow_hyphen_values = true)]
    pub viewer: Viewer,
    /// Turn of the view about the vertical axis, degrees; positive turns left.
    #[arg(help_heading = "Scene and placement", long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub yaw: f32,
    /// cylinder and cave: a tracked head at X,Y,Z (scene units, the point midway between the
    /// eyes) facing YAW degrees (as --yaw; default --yaw), away from the display's centre
    /// (--viewer): each point is drawn where the line from an eye meets the screen (the cylinder:
    /// the exact model) or the CAVE's wall.
    #[arg(help_heading = "Eyes and display", long, value_parser = parse_head, value_name = "X,Y,Z[,YAW]", allow_hyphen_values = true)]
    pub head: Option<(Vec3, Option<f32>)>,
    /// cave: the CAVE's walls, a JSON file {"walls": [{"name", "lower_left", "lower_right",
    /// "upper_left", "pixels": [W, H]}]}: each a rectangle in the scene (scene units, seen from
    /// the room: lower right to the right of lower left), drawn per eye as `NAME_left.png`,
    /// `NAME_right.png`.
    #[arg(help_heading = "Panorama", long, value_name = "FILE.json")]
    pub cave: Option<PathBuf>,
    /// Metres per scene unit: the scene (and --viewer, given in scene units) is scaled by it.
    #[arg(help_heading = "Scene and placement", long, default_value_t = 1.0)]
    pub scale: f32,
    /// Subdivision: adaptive (each edge split as --split says), adaptive:length (the paper's
    /// eq. 5, N = ceil(l/L) per edge), fixed:N (every edge N), vertex (none).
    #[arg(help_heading = "Quality", long, value_parser = Method::parse, default_value = "adaptive")]
    pub method: Method,
    /// Samples per pixel of the colour image: 1, 2, 4, 8, 16 or 32 (multisampling, averaged in
    /// linear light after tone mapping; the projection methods and slit:W; counts the adapter
    /// lacks are made up by a larger image; trace: a ray through each sample position). Depth,
    /// --hdr and the error pass stay one sample at each pixel's centre.
    /// [default: 4 for render; 1 for bench and error, the paper's geometry]
    #[arg(help_heading = "Quality", long)]
    pub samples: Option<u32>,
    /// Anisotropic texture filtering: the most probes a texture sample takes along its
    /// footprint's longer axis, 1 to 16 (1: isotropic, trilinear from the longest axis).
    /// [default: 16 for render; 1 for bench and error]
    #[arg(help_heading = "Quality", long)]
    pub anisotropy: Option<u32>,
    /// What splits an adaptive edge: error (its projected error, --max-error-px) or length (its
    /// projected length, --edge-px: the paper's eq. 5) [default: error].
    #[arg(help_heading = "Quality", long, value_parser = choice::<Split>())]
    pub split: Option<Split>,
    /// τ: the display-position error the error split allows an edge, pixels.
    #[arg(help_heading = "Quality", long, default_value_t = DEFAULT_MAX_ERROR_PX)]
    pub max_error_px: f32,
    /// L: the longest projected edge `adaptive:length` leaves, pixels (the error split keeps
    /// edges under 8·L, and under L near the eye circle).
    #[arg(help_heading = "Quality", long, default_value_t = DEFAULT_EDGE_PX)]
    pub edge_px: f32,
    /// `--method trace`: bounces of mirror and refraction rays (seed 000's Reflect_max), 0 to 8.
    #[arg(help_heading = "Lighting", long, default_value_t = DEFAULT_REFLECT_MAX)]
    pub reflect_max: u32,
    /// `--method trace`: a point light at X,Y,Z (scene coordinates) casting hard shadows, instead
    /// of the headlight at the viewer.
    #[arg(help_heading = "Lighting", long, value_parser = parse_vec3, value_name = "X,Y,Z")]
    pub light: Option<Vec3>,
    /// How surfaces are lit: auto (the glTF BRDF under the scene's KHR_lights_punctual lights
    /// where it has some, else the headlight), headlight, or pbr (the BRDF even without lights:
    /// emission and ambient only). The ray tracer's --light replaces the scene's lights.
    #[arg(help_heading = "Lighting", long, value_parser = choice::<LightingMode>(), default_value = "auto")]
    pub lighting: LightingMode,
    /// Image-based lighting: an equirectangular radiance map (.hdr or .exr; the centre column
    /// looks along −z), also shown as the background; `neutral`, the built-in grey studio (light
    /// only); or `none`. Default: `neutral` for a glTF scene or `--lighting pbr` without
    /// the scene's own lights, else none.
    #[arg(help_heading = "Lighting", long, value_name = "FILE|neutral|none")]
    pub environment: Option<String>,
    /// Turns the environment about the vertical axis, degrees: what the map shows at azimuth θ
    /// appears at θ + DEG (to put its sun where the scene wants it).
    #[arg(help_heading = "Lighting", long, default_value_t = 0.0, value_name = "DEG", allow_hyphen_values = true)]
    pub environment_yaw: f32,
    /// Adds a sun: a directional light shining from azimuth AZ (degrees from −z towards +x, the
    /// panorama's u) and elevation EL above the horizon, of LUX lux [default: 3]; it casts
    /// shadows like the scene's own lights.
    #[arg(help_heading = "Lighting", long, value_parser = parse_sun, value_name = "AZ,EL[,LUX]", allow_hyphen_values = true)]
    pub sun: Option<[f32; 3]>,
    /// The scene's lights cast no shadows (the drawing methods' shadow maps for directional and
    /// spot lights, the ray tracer's shadow rays).
    #[arg(help_heading = "Lighting", long)]
    pub no_shadows: bool,
    /// The side of a shadow map in texels (a multiple of 64; the first four lights get maps,
    /// fitted to the scene's bounding box; a point light a cube of six faces of half the side).
    #[arg(help_heading = "Lighting", long, default_value_t = twister::core::shading::shadow::DEFAULT_SHADOW_MAP_SIZE, value_name = "N")]
    pub shadow_map_size: u32,
    /// Exposure in stops: the BRDF's linear colour is scaled by 2^EV before tone mapping.
    #[arg(help_heading = "Lighting", long, default_value_t = 0.0, value_name = "EV")]
    pub exposure: f32,
    /// Tone mapping of the BRDF's colour: pbr-neutral (Khronos PBR Neutral), aces, or none (clamp).
    #[arg(help_heading = "Lighting", long, value_parser = choice::<Tonemap>(), default_value = "pbr-neutral")]
    pub tonemap: Tonemap,
    /// N_max: the largest lattice step of one piece; larger polygons are pre-split.
    #[arg(help_heading = "Quality", long, default_value_t = DEFAULT_MAX_DIV)]
    pub max_div: u32,
    /// Memory budget of the subdivision buffers, MiB; scenes that need more run in chunks.
    #[arg(help_heading = "Quality", long, default_value_t = DEFAULT_MEMORY_MB)]
    pub memory_mb: u32,
    /// Level of detail: off, or visual-field (seeds 001/000: polygon budgets and subdivision by
    /// where each object falls in the visual field of --gaze).
    #[arg(help_heading = "Quality", long, value_enum, default_value_t = LodMode::Off)]
    pub lod: LodMode,
    /// Gaze direction YAW,PITCH in degrees from straight ahead (yaw positive left, pitch up)
    /// [default: 0,0] (needs --lod visual-field)
    #[arg(help_heading = "Quality", long, value_parser = parse_gaze, allow_hyphen_values = true)]
    pub gaze: Option<Gaze>,
    /// P2'/P1: the peripheral field's smallest share of an object's triangles [default: 0.3]
    /// (needs --lod visual-field).
    #[arg(help_heading = "Quality", long)]
    pub lod_p2: Option<f32>,
    /// P3/P1: the share of an object's triangles outside the visual field [default: 0.05]
    /// (needs --lod visual-field).
    #[arg(help_heading = "Quality", long)]
    pub lod_p3: Option<f32>,
    /// D∞, metres: the budgets fall linearly with distance, kept at least P3 (eq. 2)
    /// [default: 100] (needs --lod visual-field).
    #[arg(help_heading = "Quality", long)]
    pub lod_dinf: Option<f32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    Vr4k,
    Vr6k,
    Vr8k,
    Vr16k,
}

impl Preset {
    /// Width per eye (the height is half: 360° × 180°).
    pub fn width(self) -> u32 {
        match self {
            Preset::Vr4k => 4096,
            Preset::Vr6k => 6144,
            Preset::Vr8k => 8192,
            Preset::Vr16k => 16384,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence(pub Option<f32>);

pub fn parse_convergence(s: &str) -> std::result::Result<Convergence, String> {
    if s == "parallel" {
        return Ok(Convergence(None));
    }
    match s.parse::<f32>() {
        Ok(d) if d.is_finite() && d > 0.0 => Ok(Convergence(Some(d))),
        _ => Err(format!("'{s}': expected parallel or a distance in metres")),
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoleMerge(pub Option<(f32, f32)>);

pub fn parse_pole_merge(s: &str) -> std::result::Result<PoleMerge, String> {
    if s == "off" {
        return Ok(PoleMerge(None));
    }
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [from, to] if from.is_finite() && to.is_finite() && 0.0 <= from && from < to && to <= 90.0 => {
            Ok(PoleMerge(Some((from, to))))
        }
        _ => Err(format!("'{s}': expected off or FROM,TO degrees with 0 ≤ FROM < TO ≤ 90")),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LodMode {
    Off,
    VisualField,
}

pub fn parse_gaze(s: &str) -> std::result::Result<Gaze, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [yaw, pitch] if yaw.is_finite() && pitch.is_finite() && pitch.abs() <= 89.0 => Ok(Gaze::new(yaw, pitch)),
        _ => Err(format!("'{s}': expected YAW,PITCH in degrees, pitch within ±89")),
    }
}

#[derive(Clone, Copy, Debug)]
pub enum Viewer {
    At(Vec3),
    Camera(usize),
}

pub fn parse_viewer(s: &str) -> std::result::Result<Viewer, String> {
    match s.strip_prefix("camera") {
        Some("") => Ok(Viewer::Camera(0)),
        Some(rest) => rest
            .strip_prefix(':')
            .and_then(|n| n.parse().ok())
            .map(Viewer::Camera)
            .ok_or_else(|| format!("'{s}': expected camera or camera:N")),
        None => parse_vec3(s).map(Viewer::At),
    }
}

pub fn parse_head(s: &str) -> std::result::Result<(Vec3, Option<f32>), String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok((Vec3::new(x, y, z), None)),
        [x, y, z, yaw] if v.iter().all(|c| c.is_finite()) => Ok((Vec3::new(x, y, z), Some(yaw))),
        _ => Err(format!("'{s}': expected finite numbers x,y,z or x,y,z,yaw")),
    }
}

pub fn parse_vec3(s: &str) -> std::result::Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("'{s}': expected three finite numbers x,y,z")),
    }
}

pub fn parse_sun(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    let (az, el, lux) = match v[..] {
        [az, el] => (az, el, 3.0),
        [az, el, lux] => (az, el, lux),
        _ => (f32::NAN, 0.0, 0.0),
    };
    if az.is_finite() && el.abs() <= 90.0 && lux.is_finite() && (0.0..=1e6).contains(&lux) {
        Ok([az, el, lux])
    } else {
        Err(format!("'{s}': expected AZ,EL[,LUX]: degrees, the elevation within ±90, lux from 0 to 1e6"))
    }
}

pub fn parse_rgb(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<u32> =
        s.split(',').map(|x| x.trim().parse::<u32>()).collect::<Result<_, _>>().map_err(|e| format!("'{s}': {e}"))?;
    match v[..] {
        [r, g, b] if r <= 255 && g <= 255 && b <= 255 => Ok([r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0]),
        _ => Err(format!("'{s}': expected R,G,B with each channel 0–255")),
    }
}

impl ViewArgs {
    /// The render settings these options give for a command that draws with `methods` (the
    /// viewer of `camera[:N]` is placed with the scene, by `cli::scene::prepare`).
    pub fn settings(&self, methods: &[Method]) -> Result<RenderSettings> {
        let panorama = self.panorama_kind()?;
        let walls = self.cave_file(panorama)?;
        let (width, height) = match (panorama, walls.first()) {
            (PanoramaKind::Cave, Some(wall)) => (wall.pixels[0], wall.pixels[1]),
            _ => self.size(panorama),
        };
        let projection = Projection {
            screen_radius: self.screen_radius,
            eye_radius: self.eye_radius,
            width,
            height,
            vertical: self.vertical_for(panorama, methods),
            panorama,
            convergence: self.convergence.and_then(|c| c.0),
            pole_merge: self.pole_merge.map_or(Some(DEFAULT_POLE_MERGE), |p| p.0),
            fov: self.fov.unwrap_or(180.0),
            dome_tilt: self.dome_tilt.unwrap_or(0.0),
            wall: None,
            tile: None,
            head: self.head()?,
        };
        let projection = match walls.first() {
            Some(wall) => {
                Projection { wall: Some(wall.in_display(self.scale, self.viewer_m(), self.yaw)), ..projection }
            }
            None => projection,
        };
        projection.validate().map_err(|e| match walls.first() {
            Some(wall) => crate::flags::name_wall(e, &wall.name),
            None => e,
        })?;
        if !self.yaw.is_finite() {
            return Err(Error::option("--yaw", "must be a finite number of degrees"));
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(Error::option(
                "--scale",
                format!("must be a positive number of metres per scene unit, got {}", self.scale),
            ));
        }
        let settings = RenderSettings::new(projection)
            .with_viewer(self.viewer_m())
            .with_yaw_deg(self.yaw)
            .with_method(match (self.method, self.split) {
                (Method::Adaptive(_), Some(split)) => Method::Adaptive(split),
                (method, _) => method,
            })
            .with_edge_px(self.edge_px)
            .with_max_error_px(self.max_error_px)
            .with_max_div(self.max_div)
            .with_memory_mb(self.memory_mb)
            .with_reflect_max(self.reflect_max)
            .with_light(self.light)
            .with_lighting(self.lighting)
            .with_exposure_ev(self.exposure)
            .with_shadows(!self.no_shadows)
            .with_shadow_map_size(self.shadow_map_size)
            .with_environment_yaw_deg(self.environment_yaw)
            .with_tonemap(self.tonemap)
            .with_samples(self.samples.unwrap_or(1))
            .with_anisotropy(self.anisotropy.unwrap_or(1));
        settings.validate()?;
        Ok(settings)
    }

    /// `--panorama` (equirect under `--preset`), and the options that need another panorama
    /// refused.
    fn panorama_kind(&self) -> Result<PanoramaKind> {
        let panorama = match (self.panorama, self.preset) {
            (Some(p), Some(_)) if p != PanoramaKind::Equirect => {
                return Err(Error::option("--preset", "sizes the full sphere: use it with --panorama equirect"))
            }
            (Some(p), _) => p,
            (None, Some(_)) => PanoramaKind::Equirect,
            (None, None) => PanoramaKind::Cylinder,
        };
        if panorama == PanoramaKind::Cylinder {
            if self.convergence.is_some() {
                return Err(Error::option("--convergence", "needs --panorama equirect or vr180"));
            }
            if self.pole_merge.is_some() {
                return Err(Error::option("--pole-merge", "needs --panorama equirect or vr180"));
            }
        }
        if panorama != PanoramaKind::Fisheye {
            if self.fov.is_some() {
                return Err(Error::option("--fov", "needs --panorama fisheye"));
            }
            if self.dome_tilt.is_some() {
                return Err(Error::option("--dome-tilt", "needs --panorama fisheye"));
            }
        }
        Ok(panorama)
    }

    /// The image's size per eye: `--preset`, else `--width`/`--height` with each panorama's
    /// defaults (a CAVE's walls give their own).
    fn size(&self, panorama: PanoramaKind) -> (u32, u32) {
        if let Some(preset) = self.preset {
            return (preset.width(), preset.width() / 2);
        }
        // The paper's 3168 × 600 on the cylinder (600 rows whatever the width); the cubemap's
        // faces of 1024 (the default sphere's 4096 pixels a turn at their centres); else 4096
        // pixels wide and the panorama's own height for its width.
        let width = self.width.unwrap_or(match panorama {
            PanoramaKind::Cylinder => 3168,
            PanoramaKind::Cubemap | PanoramaKind::Cave => 3072,
            _ => 4096,
        });
        let height = match panorama {
            PanoramaKind::Cylinder => 600,
            PanoramaKind::Cave => 2 * width / 3,
            _ => panorama.model().default_size(width)[1],
        };
        (width, self.height.unwrap_or(height))
    }

    /// `--head`: the tracked head relative to the display's centre (`--viewer x,y,z`).
    fn head(&self) -> Result<Option<Head>> {
        match (self.head, self.viewer) {
            (None, _) => Ok(None),
            (Some(_), Viewer::Camera(_)) => {
                Err(Error::option("--head", "needs the display's centre as --viewer x,y,z"))
            }
            (Some((at, yaw)), Viewer::At(viewer)) => {
                Ok(Some(Head::relative(at * self.scale, yaw.unwrap_or(self.yaw), viewer * self.scale, self.yaw)))
            }
        }
    }

    /// `--viewer` in metres (a camera's place: the origin until the scene is prepared, by
    /// `scene::prepare`).
    pub(crate) fn viewer_m(&self) -> Vec3 {
        match self.viewer {
            Viewer::At(p) => p * self.scale,
            Viewer::Camera(_) => Vec3::ZERO,
        }
    }

    /// The vertical model: as given, else the paper's, except where `trace` draws the cylinder:
    /// the paper's model (v = R_T·y/r) has no ray per pixel, so the exact one is used and a
    /// `note:` line says so.
    fn vertical_for(&self, panorama: PanoramaKind, methods: &[Method]) -> Vertical {
        match self.vertical {
            Some(vertical) => vertical,
            // A tracked head's line from the eye to the screen is the exact model.
            None if self.head.is_some() => Vertical::Exact,
            None if panorama == PanoramaKind::Cylinder && methods.contains(&Method::Trace) => {
                eprintln!(
                    "note: trace follows each pixel's ray, which the paper's vertical model (v = R_T·y/r) does not \
                     have: the cylinder is drawn with --vertical exact"
                );
                Vertical::Exact
            }
            None => Vertical::Paper,
        }
    }

    /// The environment that lights the scene (see `--environment`), prepared.
    pub fn environment(&self, scene: &twister::Scene) -> Result<Option<PreparedEnvironment>> {
        use twister::core::shading::environment::Environment;
        if self.lighting == LightingMode::Headlight && self.environment.as_deref().is_some_and(|e| e != "none") {
            return Err(Error::option(
                "--environment",
                "lights the glTF BRDF, which --lighting headlight turns off: use --lighting auto or pbr",
            ));
        }
        let wants_default = scene.lights.is_empty()
            && match self.lighting {
                LightingMode::Auto => scene.physically_based,
                LightingMode::Pbr => true,
                LightingMode::Headlight => false,
            };
        Ok(match self.environment.as_deref() {
            Some("none") => None,
            Some("neutral") => Some(Environment::neutral().prepare_cached()),
            Some(file) => Some(PreparedEnvironment {
                background: true,
                ..Environment::load(std::path::Path::new(file))?.prepare_cached()
            }),
            None if wants_default => Some(Environment::neutral().prepare_cached()),
            None => None,
        })
    }

    /// `--light` is refused unless one of `methods` traces rays (it would do nothing).
    pub fn check_light(&self, methods: &[Method]) -> Result<()> {
        if self.light.is_some() && !methods.contains(&Method::Trace) {
            return Err(Error::option("--light", "lights the ray tracer: use it with --method trace"));
        }
        Ok(())
    }

    /// The level-of-detail parameters and gaze with `--lod visual-field`; the LOD options are
    /// refused without it (they would do nothing).
    pub fn lod(&self) -> Result<Option<(LodParams, Gaze)>> {
        match self.lod {
            LodMode::Off => {
                let given = [
                    ("--gaze", self.gaze.is_some()),
                    ("--lod-p2", self.lod_p2.is_some()),
                    ("--lod-p3", self.lod_p3.is_some()),
                    ("--lod-dinf", self.lod_dinf.is_some()),
                ];
                match given.iter().find(|(_, g)| *g) {
                    Some((option, _)) => Err(Error::option(option, "needs --lod visual-field")),
                    None => Ok(None),
                }
            }
            LodMode::VisualField => {
                let d = LodParams::default();
                let params = LodParams {
                    p2: self.lod_p2.unwrap_or(d.p2),
                    p3: self.lod_p3.unwrap_or(d.p3),
                    d_inf: self.lod_dinf.unwrap_or(d.d_inf),
                };
                params.validate()?;
                Ok(Some((params, self.gaze.unwrap_or(Gaze::new(0.0, 0.0)))))
            }
        }
    }
}

/// `twister render`'s options: the scene, the view, the outputs, and a sequence's frames.
#[derive(Args, Clone)]
#[command(allow_negative_numbers = true)]
pub struct RenderArgs {
    /// Scene to render: a .obj, .gltf or .glb file, or builtin:demo, builtin:box-room, builtin:cube, builtin:sphere100, builtin:sphere1024, builtin:triangle@D.
    #[arg(default_value = "builtin:demo")]
    pub scene: String,
    /// Move and scale the scene so that it stands DIST metres ahead, filling the screen height.
    #[arg(help_heading = "Scene and placement", long, value_name = "DIST")]
    pub fit: Option<f32>,
    /// Output folder.
    #[arg(help_heading = "Scene and placement", long, default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub view: ViewArgs,
    /// Output layout: eyes (left.png, right.png), top-bottom (stereo_TB.png, left eye on top;
    /// the sphere's stereo_360_TB.png), side-by-side (stereo_LR.png, left eye on the left;
    /// vr180's stereo_180_LR.png), twister (four W/2×H images, the cylinder), 12x1 (the
    /// cubemap's twelve faces in one strip, left eye's first: stereo_cubemap_12x1.png)
    /// [default: eyes; top-bottom for equirect and cubemap; side-by-side for vr180].
    #[arg(help_heading = "Output", long, value_parser = choice::<Layout>())]
    pub layout: Option<Layout>,
    /// Image format: png or jpg (full-sphere images carry GPano XMP metadata in both).
    #[arg(help_heading = "Output", long, value_parser = choice::<ImageFormat>(), default_value = "png")]
    pub format: ImageFormat,
    /// JPEG quality, 1–100 (with --format jpg).
    #[arg(help_heading = "Output", long, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub quality: Option<u8>,
    /// Also write each eye's distance from its eye point along the ray, metres, as 32-bit float
    /// OpenEXR (channel Z, +inf where no surface): left_depth.exr/right_depth.exr, depth_TB.exr
    /// or depth_LR.exr, following the layout.
    #[arg(help_heading = "Output", long)]
    pub depth: bool,
    /// Also write each eye's linear colour (× 2^EV, before tone mapping, not clamped) as 32-bit
    /// float OpenEXR (channels R, G, B): left_hdr.exr, right_hdr.exr. Drawn into a float colour
    /// target beside the display colour, in the same frame; the projection methods only.
    #[arg(help_heading = "Output", long)]
    pub hdr: bool,
    /// fisheye: outside the circle transparent (alpha 0) instead of the background colour; PNG.
    #[arg(help_heading = "Output", long)]
    pub alpha: bool,
    /// The largest tile a frame is drawn in, pixels a side (at least 16): a frame larger than
    /// this, than the adapter draws at once, or than 512 MiB of colour is drawn in tiles and its
    /// images (and --depth, --hdr) are written as rows arrive, in bounded memory [default: the
    /// adapter's].
    #[arg(help_heading = "Output", long, value_name = "PIXELS")]
    pub max_tile: Option<u32>,
    /// Background colour R,G,B, each 0–255.
    #[arg(help_heading = "Output", long, value_parser = parse_rgb, default_value = "26,26,31")]
    pub background: [f32; 3],
    /// Write render statistics as JSON to this file.
    #[arg(help_heading = "Output", long)]
    pub stats: Option<PathBuf>,
    /// With --lod visual-field: tint each object by its level and draw the central-field
    /// (white) and visual-field (orange) boundaries.
    #[arg(help_heading = "Output", long)]
    pub lod_overlay: bool,
    /// Render frames A to B (inclusive) of the animation timeline (frame k at k / FPS seconds)
    /// into numbered files: frame_000123_TB.png (top-bottom), frame_000123_left.png … (see
    /// *Sequences* in the README); `N` alone renders frame N.
    #[arg(help_heading = "Animation and farm", long, value_parser = parse_frames, value_name = "A..B")]
    pub frames: Option<(u32, u32)>,
    /// Frames per second of the sequence's timeline.
    #[arg(help_heading = "Animation and farm", long, default_value_t = 30.0)]
    pub fps: f32,
    /// The animation a sequence plays, by name or index [default: the file's first].
    #[arg(help_heading = "Animation and farm", long, value_name = "NAME|INDEX")]
    pub animation: Option<String>,
    /// Skip the frames whose files all exist (a sequence resumed after a stop).
    #[arg(help_heading = "Animation and farm", long)]
    pub resume: bool,
    /// Render only this shard's frames: I/N, frames whose index from A is ≡ I (mod N), or the
    /// I-th of N contiguous blocks with --shard-mode blocks (a job array's task id).
    #[arg(help_heading = "Animation and farm", long, value_parser = parse_shard, value_name = "I/N")]
    pub shard: Option<(u32, u32)>,
    /// With --frames: also encode the sequence as an MP4 video (H.264 by the system's ffmpeg)
    /// with Google's spherical video metadata (st3d stereo mode; sv3d equirectangular on the
    /// sphere); needs a one-image layout (top-bottom or side-by-side). After --shard runs, run
    /// once more with --resume --video to encode.
    #[arg(help_heading = "Animation and farm", long, value_name = "FILE.mp4")]
    pub video: Option<PathBuf>,
    /// With --frames and --lod visual-field: the gaze over time, a CSV of time,yaw,pitch rows
    /// (seconds, degrees as --gaze): each frame's level of detail follows the tracked viewer.
    #[arg(help_heading = "Animation and farm", long, value_name = "FILE.csv")]
    pub gaze_path: Option<PathBuf>,
    /// With --frames: the viewer over time, a CSV of time,x,y,z[,yaw] rows (seconds; the place
    /// in scene units as --viewer; degrees added to --yaw), blended linearly between rows.
    #[arg(help_heading = "Animation and farm", long, value_name = "FILE.csv")]
    pub viewer_path: Option<PathBuf>,
    /// With --frames, the cylinder: the tracked head over time, a CSV of time,x,y,z[,yaw] rows
    /// (seconds; the head in scene units as --head; its yaw in degrees, default --yaw), blended
    /// linearly between rows.
    #[arg(help_heading = "Animation and farm", long, value_name = "FILE.csv")]
    pub head_path: Option<PathBuf>,
    /// How --shard splits the frames.
    #[arg(help_heading = "Animation and farm", long, value_enum, default_value_t = ShardMode::Interleave)]
    pub shard_mode: ShardMode,
}

/// `--frames`: the first and last frame, inclusive.
pub fn parse_frames(s: &str) -> std::result::Result<(u32, u32), String> {
    let (a, b) = s.split_once("..").unwrap_or((s, s));
    let (a, b) = (a.trim().parse::<u32>(), b.trim().parse::<u32>());
    match (a, b) {
        (Ok(a), Ok(b)) if a <= b && b < 100_000_000 => Ok((a, b)),
        _ => Err(format!("'{s}': expected A..B, frame numbers from 0 with A ≤ B (or one frame N)")),
    }
}

/// `--shard I/N`.
pub fn parse_shard(s: &str) -> std::result::Result<(u32, u32), String> {
    let parsed = s.split_once('/').map(|(i, n)| (i.trim().parse::<u32>(), n.trim().parse::<u32>()));
    match parsed {
        Some((Ok(i), Ok(n))) if n > 0 && i < n => Ok((i, n)),
        _ => Err(format!("'{s}': expected I/N with 0 ≤ I < N (e.g. $SLURM_ARRAY_TASK_ID/$N)")),
    }
}

/// How `--shard` splits the frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ShardMode {
    /// Frame k goes to shard k mod N.
    #[default]
    Interleave,
    /// N contiguous blocks, as even as can be.
    Blocks,
}
