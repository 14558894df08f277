//! Exactness by random search: random closed rooms holding random closed objects, seen from
//! random viewers through random panoramas, methods, sizes, eye models, tracked heads and
//! levels of detail ([`SearchCase`], drawn by the proptest strategy [`case_strategy`], so that a
//! failure shrinks to a small case), and the promises checked on each:
//! - `topology`: the subdivision's CPU twin is watertight and loses nothing visible
//!   ([`topology::Topology`], against the input mesh);
//! - `background`: the real renderer (one sample, a marker background) shows no background
//!   pixel: the room is closed around every eye (inside the fisheye's circle);
//! - `twin`: the GPU's subdivision is the twin's ([`twin::compare_subdivided`]).
//!
//! The property tests (`tests/search.rs`, `cpu::subdivide` and `core::detail::lod` tests) and
//! `twister bench search` both draw their cases here.

pub mod checks;
pub mod topology;
pub mod twin;

pub use checks::{check, check_cpu, check_gpu, drawn_scene, Check, Drawn, Failure};

use glam::Vec3;
use proptest::prelude::*;
use proptest::strategy::{BoxedStrategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use crate::core::choice::Choice;
use crate::core::detail::lod::{LodChain, LodParams, LodSelection};
use crate::core::detail::visual_field::Gaze;
use crate::core::panoramas::cave::NamedWall;
use crate::core::panoramas::head::Head;
use crate::core::panoramas::projection::{PanoramaKind, Projection, Vertical, DEFAULT_POLE_MERGE};
use crate::core::scenes::scene::Scene;
use crate::core::scenes::shapes::ClosedMesh;
use crate::core::settings::{Method, RenderSettings, Split};

/// The marker background: no surface of a case has this colour.
pub const MARKER: [f32; 3] = [1.0, 0.0, 1.0];

/// The panoramas searched; the cylinder seen by a tracked head counts as its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SearchPanorama {
    Cylinder,
    CylinderHead,
    Equirect,
    Vr180,
    Fisheye,
    Cubemap,
    Cave,
}

impl SearchPanorama {
    pub const ALL: [SearchPanorama; 7] = [
        SearchPanorama::Cylinder,
        SearchPanorama::CylinderHead,
        SearchPanorama::Equirect,
        SearchPanorama::Vr180,
        SearchPanorama::Fisheye,
        SearchPanorama::Cubemap,
        SearchPanorama::Cave,
    ];

    pub fn name(self) -> &'static str {
        match self {
            SearchPanorama::Cylinder => "cylinder",
            SearchPanorama::CylinderHead => "cylinder-head",
            SearchPanorama::Equirect => "equirect",
            SearchPanorama::Vr180 => "vr180",
            SearchPanorama::Fisheye => "fisheye",
            SearchPanorama::Cubemap => "cubemap",
            SearchPanorama::Cave => "cave",
        }
    }

    pub fn parse(s: &str) -> Option<SearchPanorama> {
        SearchPanorama::ALL.into_iter().find(|p| p.name() == s)
    }

    /// The panorama it draws: the one of its name (the cylinder with a tracked head: the
    /// cylinder).
    pub fn kind(self) -> PanoramaKind {
        let name = if self == SearchPanorama::CylinderHead { SearchPanorama::Cylinder.name() } else { self.name() };
        Choice::from_name(name).expect("every searched panorama is one of the library's")
    }
}

/// The methods searched, by family (`fixed:N` and the adaptive rules with random N, L, τ).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SearchMethod {
    Vertex,
    Fixed,
    Adaptive,
    AdaptiveLength,
}

impl SearchMethod {
    pub const ALL: [SearchMethod; 4] =
        [SearchMethod::Vertex, SearchMethod::Fixed, SearchMethod::Adaptive, SearchMethod::AdaptiveLength];

    pub fn name(self) -> &'static str {
        match self {
            SearchMethod::Vertex => "vertex",
            SearchMethod::Fixed => "fixed",
            SearchMethod::Adaptive => "adaptive",
            SearchMethod::AdaptiveLength => "adaptive:length",
        }
    }

    pub fn parse(s: &str) -> Option<SearchMethod> {
        SearchMethod::ALL.into_iter().find(|m| m.name() == s)
    }

    pub fn of(method: Method) -> SearchMethod {
        match method {
            Method::Vertex => SearchMethod::Vertex,
            Method::Fixed(_) => SearchMethod::Fixed,
            Method::Adaptive(Split::Error) => SearchMethod::Adaptive,
            _ => SearchMethod::AdaptiveLength,
        }
    }

    /// Whether the panorama takes the method (the fisheye refuses the methods that measure no
    /// edge: `RenderSettings::validate`).
    pub fn takes(self, panorama: SearchPanorama) -> bool {
        panorama != SearchPanorama::Fisheye || matches!(self, SearchMethod::Adaptive | SearchMethod::AdaptiveLength)
    }
}

/// A closed object in the room: its shape, its centre as a share of the room's half size
/// (each coordinate in −1..1 about the room's centre) and its size as a share of the room's
/// smallest half size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectSpec {
    pub shape: ShapeSpec,
    pub at: [f32; 3],
    pub size: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeSpec {
    Icosphere(u32),
    Box(u32),
    Torus(u32, u32),
}

impl ShapeSpec {
    /// The radius of the unit shape's bounding sphere about its centre (`ClosedMesh::placed`
    /// scales it by the object's size).
    fn bounding_radius(self) -> f32 {
        self.mesh().positions.iter().map(|p| p.length()).fold(0.0, f32::max)
    }

    fn mesh(self) -> ClosedMesh {
        match self {
            ShapeSpec::Icosphere(l) => ClosedMesh::icosphere(l),
            ShapeSpec::Box(g) => ClosedMesh::grid_box(g),
            ShapeSpec::Torus(n, m) => ClosedMesh::torus(n, m),
        }
    }
}

/// One random case: the scene (a closed room of grid faces around the viewer, closed objects
/// in it) and every setting the frame is drawn with. Lengths in metres (scene units).
#[derive(Clone, Debug, PartialEq)]
pub struct SearchCase {
    pub panorama: SearchPanorama,
    pub method: Method,
    pub edge_px: f32,
    pub max_error_px: f32,
    pub max_div: u32,
    /// The room: quads per face edge, half sizes, and its centre relative to the viewer.
    pub room_grid: u32,
    pub room_half: [f32; 3],
    pub room_offset: [f32; 3],
    pub objects: Vec<ObjectSpec>,
    pub viewer: [f32; 3],
    pub yaw_deg: f32,
    /// Image width; the height follows the panorama (the cylinder's is `height`).
    pub width: u32,
    pub height: u32,
    pub screen_radius: f32,
    pub eye_radius: f32,
    pub vertical: Vertical,
    pub convergence: Option<f32>,
    pub pole_merge: bool,
    pub fov: f32,
    pub dome_tilt: f32,
    /// A tracked head (the cylinder's, the CAVE's): its offset from the viewer and its yaw.
    pub head: Option<([f32; 3], f32)>,
    /// The CAVE: the cube's half size about the viewer and the wall drawn (0..6).
    pub cave_half: f32,
    pub cave_wall: usize,
    /// The level of detail's gaze (yaw, pitch), if it is on.
    pub gaze: Option<(f32, f32)>,
}

impl SearchCase {
    /// The scene: the room (object 0), then the objects.
    pub fn scene(&self) -> Scene {
        let mut scene = Scene::new("search case");
        let viewer = Vec3::from(self.viewer);
        let half = Vec3::from(self.room_half);
        let centre = viewer + Vec3::from(self.room_offset);
        let room = ClosedMesh::grid_box(self.room_grid);
        let room = ClosedMesh {
            name: "room".into(),
            positions: room.positions.iter().map(|&p| p * half + centre).collect(),
            ..room
        };
        room.add_to(&mut scene, [0.6, 0.62, 0.58, 1.0]);
        for (k, o) in self.objects.iter().enumerate() {
            let mesh = o.shape.mesh().placed(centre + Vec3::from(o.at) * half, o.size * half.min_element());
            let mesh = ClosedMesh { name: format!("object {k} ({})", mesh.name), ..mesh };
            let shade = 0.3 + 0.1 * (k % 4) as f32;
            mesh.add_to(&mut scene, [shade, 0.5, 0.9 - shade, 1.0]);
        }
        scene
    }

    /// The head in the display's frame, where the case has one.
    fn head_at(&self) -> Option<Head> {
        let viewer = Vec3::from(self.viewer);
        self.head.map(|(offset, yaw)| Head::relative(viewer + Vec3::from(offset), yaw, viewer, self.yaw_deg))
    }

    /// The CAVE's walls: the cube of half size `cave_half` about the viewer (scene frame).
    pub fn cave_walls(&self) -> Vec<NamedWall> {
        let (c, v) = (self.cave_half, Vec3::from(self.viewer));
        let p = |x: f32, y: f32, z: f32| (v + c * Vec3::new(x, y, z)).to_array();
        let wall = |name: &str, ll, lr, ul| NamedWall {
            name: name.into(),
            lower_left: ll,
            lower_right: lr,
            upper_left: ul,
            pixels: [self.width; 2],
        };
        vec![
            wall("front", p(-1.0, -1.0, -1.0), p(1.0, -1.0, -1.0), p(-1.0, 1.0, -1.0)),
            wall("left", p(-1.0, -1.0, 1.0), p(-1.0, -1.0, -1.0), p(-1.0, 1.0, 1.0)),
            wall("right", p(1.0, -1.0, -1.0), p(1.0, -1.0, 1.0), p(1.0, 1.0, -1.0)),
            wall("back", p(1.0, -1.0, 1.0), p(-1.0, -1.0, 1.0), p(1.0, 1.0, 1.0)),
            wall("floor", p(-1.0, -1.0, 1.0), p(1.0, -1.0, 1.0), p(-1.0, -1.0, -1.0)),
            wall("ceiling", p(-1.0, 1.0, -1.0), p(1.0, 1.0, -1.0), p(-1.0, 1.0, 1.0)),
        ]
    }

    pub fn projection(&self) -> Projection {
        let base = Projection {
            screen_radius: self.screen_radius,
            eye_radius: self.eye_radius,
            vertical: self.vertical,
            convergence: self.convergence,
            pole_merge: self.pole_merge.then_some(DEFAULT_POLE_MERGE),
            ..Projection::default()
        };
        match self.panorama {
            SearchPanorama::Cylinder => Projection { width: self.width, height: self.height, ..base },
            SearchPanorama::CylinderHead => {
                Projection { width: self.width, height: self.height, head: self.head_at(), ..base }
            }
            SearchPanorama::Equirect => Projection::equirect(self.width).with_eyes(&base),
            SearchPanorama::Vr180 => Projection::vr180(self.width).with_eyes(&base),
            SearchPanorama::Fisheye => Projection {
                fov: self.fov,
                dome_tilt: self.dome_tilt,
                ..Projection::fisheye(self.width).with_eyes(&base)
            },
            SearchPanorama::Cubemap => Projection::cubemap(3 * (self.width / 3)).with_eyes(&base),
            SearchPanorama::Cave => {
                let wall = &self.cave_walls()[self.cave_wall];
                Projection {
                    panorama: SearchPanorama::Cave.kind(),
                    width: self.width,
                    height: self.width,
                    wall: Some(wall.in_display(1.0, Vec3::from(self.viewer), self.yaw_deg)),
                    head: self.head_at(),
                    vertical: Vertical::Exact,
                    ..base
                }
            }
        }
    }

    /// The frame's settings: one sample, trilinear, the marker background.
    pub fn settings(&self) -> RenderSettings {
        RenderSettings::new(self.projection())
            .with_viewer(Vec3::from(self.viewer))
            .with_yaw_deg(self.yaw_deg)
            .with_method(self.method)
            .with_edge_px(self.edge_px)
            .with_max_error_px(self.max_error_px)
            .with_max_div(self.max_div)
            .with_samples(1)
            .with_anisotropy(1)
            .with_background(MARKER)
    }

    /// The level of detail's selection for the case's gaze, where it has one.
    pub fn lod(&self, scene: &Scene, settings: &RenderSettings) -> Option<LodSelection> {
        let (yaw, pitch) = self.gaze?;
        let params = LodParams::default();
        Some(LodChain::build(scene, params.p3).select(scene, settings.view(), &Gaze::new(yaw, pitch), &params))
    }

    /// One line naming the case's settings.
    pub fn describe(&self) -> String {
        format!(
            "{} {} {}x{} L={:.1} τ={:.2} N_max={} room {}×{:?} viewer {:?} yaw {:.0}, {} objects, d_e={:.3} R_T={:.2} {:?}{}{}{}",
            self.panorama.name(),
            self.method.name(),
            self.width,
            self.height,
            self.edge_px,
            self.max_error_px,
            self.max_div,
            self.room_grid,
            self.room_half,
            self.viewer,
            self.yaw_deg,
            self.objects.len(),
            self.eye_radius,
            self.screen_radius,
            self.vertical,
            self.head.map(|h| format!(" head {h:?}")).unwrap_or_default(),
            if self.panorama == SearchPanorama::Fisheye { format!(" fov {:.0} tilt {:.0}", self.fov, self.dome_tilt) } else { String::new() },
            self.gaze.map(|g| format!(" lod gaze {g:?}")).unwrap_or_default(),
        )
    }
}

impl Projection {
    /// This projection with `eyes`' eye model (radii, vertical model, convergence, pole merge).
    fn with_eyes(self, eyes: &Projection) -> Projection {
        Projection {
            screen_radius: eyes.screen_radius,
            eye_radius: eyes.eye_radius,
            vertical: eyes.vertical,
            convergence: eyes.convergence,
            pole_merge: eyes.pole_merge,
            ..self
        }
    }
}

/// The random cases of the panoramas and methods given (empty: all), sizes up to `max_width`.
pub fn case_strategy(
    panoramas: &[SearchPanorama],
    methods: &[SearchMethod],
    max_width: u32,
) -> BoxedStrategy<SearchCase> {
    let panoramas: Vec<SearchPanorama> =
        if panoramas.is_empty() { SearchPanorama::ALL.to_vec() } else { panoramas.to_vec() };
    let methods: Vec<SearchMethod> = if methods.is_empty() { SearchMethod::ALL.to_vec() } else { methods.to_vec() };
    let pairs: Vec<(SearchPanorama, SearchMethod)> =
        panoramas.iter().flat_map(|&p| methods.iter().filter(move |m| m.takes(p)).map(move |&m| (p, m))).collect();
    assert!(!pairs.is_empty(), "no panorama takes the methods asked for");
    let max_width = max_width.max(48);
    let shape = prop_oneof![
        (0u32..=2).prop_map(ShapeSpec::Icosphere),
        (1u32..=3).prop_map(ShapeSpec::Box),
        (3u32..=12, 3u32..=8).prop_map(|(n, m)| ShapeSpec::Torus(n, m)),
    ];
    let object = (shape, proptest::array::uniform3(-0.9f32..0.9), 0.05f32..0.6)
        .prop_map(|(shape, at, size)| ObjectSpec { shape, at, size });
    let method = (0usize..1000, 1u32..=12, 4.0f32..64.0, 0.1f32..2.0, 1u32..=16);
    let room = (1u32..=4, proptest::array::uniform3(1.5f32..8.0), proptest::array::uniform3(-1.0f32..1.0));
    let view = (proptest::array::uniform3(-3.0f32..3.0), -180.0f32..180.0, 48u32..=max_width, 0.0f32..1.0);
    let eyes = (
        0.5f32..3.0,
        prop_oneof![Just(0.0f32), 0.0f32..0.1],
        any::<bool>(),
        proptest::option::of(0.5f32..5.0),
        any::<bool>(),
    );
    let dome = (90.0f32..=360.0, -30.0f32..30.0);
    let head = (proptest::array::uniform3(-1.0f32..1.0), -180.0f32..180.0, 1.0f32..2.0, 0usize..6);
    let gaze = proptest::option::of((-180.0f32..180.0, -80.0f32..80.0));
    (
        proptest::sample::select(pairs),
        method,
        room,
        proptest::collection::vec(object, 0..=3),
        view,
        eyes,
        dome,
        head,
        gaze,
    )
        .prop_map(assemble)
        .boxed()
}

/// What the strategy draws for one case, before it is assembled ([`assemble`]).
type Draw = (
    (SearchPanorama, SearchMethod),
    (usize, u32, f32, f32, u32),
    (u32, [f32; 3], [f32; 3]),
    Vec<ObjectSpec>,
    ([f32; 3], f32, u32, f32),
    (f32, f32, bool, Option<f32>, bool),
    (f32, f32),
    ([f32; 3], f32, f32, usize),
    Option<(f32, f32)>,
);

/// A case from what the strategy drew: the method, a head and a room that holds the eyes, the
/// head and the CAVE, the sizes each panorama takes.
fn assemble(
    (
        (panorama, family),
        (fixed_pick, fixed_n, edge_px, tau, max_div),
        (room_grid, room_half, room_at),
        objects,
        (viewer, yaw_deg, width, tall),
        (screen_radius, eye_radius, exact, convergence, pole_merge),
        (fov, tilt),
        (head_at, head_yaw, cave_half, cave_wall),
        gaze,
    ): Draw,
) -> SearchCase {
    let method = match family {
        SearchMethod::Vertex => Method::Vertex,
        SearchMethod::Fixed => Method::Fixed(if fixed_pick < 100 { 13 + fixed_pick as u32 % 20 } else { fixed_n }),
        SearchMethod::Adaptive => Method::Adaptive(Split::Error),
        SearchMethod::AdaptiveLength => Method::Adaptive(Split::Length),
    };
    // A tracked head within 60 % of the screen's radius (the cylinder) or of the
    // CAVE's half size; the room holds it, the eyes and the CAVE with 0.5 m to spare.
    let (head, reach) = match panorama {
        SearchPanorama::CylinderHead => {
            let r = 0.6 * screen_radius;
            (Some(([head_at[0] * r, 0.3 * head_at[1], head_at[2] * r], head_yaw)), r + 0.3)
        }
        SearchPanorama::Cave => {
            let r = 0.6 * cave_half;
            (Some((head_at.map(|c| c * r), head_yaw)), cave_half * 3f32.sqrt())
        }
        _ => (None, 0.2),
    };
    let room_half = room_half.map(|h| h.max(reach + 0.5 + 2.0 * eye_radius));
    let room_offset = [0, 1, 2].map(|i| room_at[i] * (room_half[i] - reach - 0.5).max(0.0));
    let fov = if tilt.abs() > 0.0 { fov.min(330.0) } else { fov };
    let sphere = panorama.kind().is_sphere();
    let objects = clear_of_the_eyes(objects, room_offset, room_half, reach + 2.0 * eye_radius + 0.1);
    let case = SearchCase {
        panorama,
        method,
        edge_px,
        max_error_px: tau,
        max_div,
        room_grid,
        room_half,
        room_offset,
        objects,
        viewer,
        yaw_deg,
        width: if panorama == SearchPanorama::Cubemap { (width / 3).max(16) * 3 } else { width },
        height: ((width as f32 * (0.1 + 0.5 * tall)) as u32).max(16),
        screen_radius,
        eye_radius,
        vertical: if exact || panorama == SearchPanorama::CylinderHead { Vertical::Exact } else { Vertical::Paper },
        convergence: convergence.filter(|_| sphere),
        pole_merge,
        fov,
        dome_tilt: tilt,
        head,
        cave_half,
        cave_wall,
        gaze,
    };
    fit_a_tilted_dome(case)
}

/// Objects clear of the eyes (and the head's reach) by `clearance`: geometry through the eye
/// circle is outside every method's promise (README), and there the error split cuts its edges
/// into up to `MAX_EDGE_DIVISIONS` parts (a box through the eyes made 8.6 million triangles). An
/// object whose bounding sphere comes closer is shrunk about its centre, or left out when too
/// little of it would remain.
fn clear_of_the_eyes(
    objects: Vec<ObjectSpec>,
    room_offset: [f32; 3],
    room_half: [f32; 3],
    clearance: f32,
) -> Vec<ObjectSpec> {
    let min_half = room_half[0].min(room_half[1]).min(room_half[2]);
    objects
        .into_iter()
        .filter_map(|o| {
            let centre = Vec3::from(room_offset) + Vec3::from(o.at) * Vec3::from(room_half);
            let radius = (centre.length() - clearance).min(o.shape.bounding_radius() * o.size * min_half);
            let size = radius / (o.shape.bounding_radius() * min_half);
            (size >= 0.02).then_some(ObjectSpec { size, ..o })
        })
        .collect()
}

/// A tilted dome keeps its cone around the point opposite its axis: L and τ within what its
/// margin holds (`RenderSettings::validate` refuses more).
fn fit_a_tilted_dome(case: SearchCase) -> SearchCase {
    if case.panorama != SearchPanorama::Fisheye || case.dome_tilt == 0.0 {
        return case;
    }
    let p = case.projection();
    let room = 0.95 * p.max_chord_dip_px();
    let edge_px = case.edge_px.min((8.0 * 0.5 * p.width as f32 * room).sqrt() / 1.5).max(1.0);
    let max_error_px = case.max_error_px.min(room / 4.0).max(0.01);
    SearchCase { edge_px, max_error_px, ..case }
}

/// The property tests' configuration: `default_cases` cases (`PROPTEST_CASES` where set) from
/// a fixed seed (`PROPTEST_RNG_SEED` where set), so that the default suite runs the same list
/// everywhere; failures persisted in `regressions` (a path under `proptest-regressions/`,
/// relative to the package's root, where `cargo test` runs).
pub fn test_config(default_cases: u32, regressions: &'static str) -> Config {
    let config = Config::default();
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(default_cases);
    let rng_seed = match config.rng_seed {
        proptest::test_runner::RngSeed::Random => proptest::test_runner::RngSeed::Fixed(58),
        fixed => fixed,
    };
    let failure_persistence = Some(Box::new(proptest::test_runner::FileFailurePersistence::Direct(regressions))
        as Box<dyn proptest::test_runner::FailurePersistence>);
    Config { cases, rng_seed, failure_persistence, ..config }
}

/// A deterministic stream of cases from a seed (`twister bench search --seed S`): case k is the
/// strategy's k-th draw, and a failing one shrinks by the strategy's own simplification.
pub struct CaseStream {
    runner: TestRunner,
    strategy: BoxedStrategy<SearchCase>,
}

impl CaseStream {
    pub fn new(seed: u64, strategy: BoxedStrategy<SearchCase>) -> CaseStream {
        let mut bytes = [0u8; 32];
        bytes[..8].copy_from_slice(&seed.to_le_bytes());
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &bytes);
        CaseStream { runner: TestRunner::new_with_rng(Config::default(), rng), strategy }
    }

    /// The next case, with its tree for shrinking.
    pub fn next_tree(&mut self) -> Box<dyn ValueTree<Value = SearchCase>> {
        Box::new(self.strategy.new_tree(&mut self.runner).expect("the search's strategy rejects no case"))
    }
}

/// Shrinks a failing case: simplifies it while `fails` still holds (at most `steps` tries);
/// the smallest failing case found.
pub fn shrink(
    mut tree: Box<dyn ValueTree<Value = SearchCase>>,
    steps: usize,
    fails: impl Fn(&SearchCase) -> bool,
) -> SearchCase {
    let mut smallest = tree.current();
    for _ in 0..steps {
        if !tree.simplify() {
            break;
        }
        let case = tree.current();
        if fails(&case) {
            smallest = case;
        } else if !tree.complicate() {
            break;
        }
    }
    smallest
}
