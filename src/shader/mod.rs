//! The WGSL side's interface, with no GPU in it: the stage registry, WGSL composition, the
//! shared constants and the plain-old-data structs.
//!
//! **A stage** is one WGSL file in `shaders/` (its entry points) or, for a stage of several
//! passes (`subdivide`), one file per pass in `shaders/NAME/` (as vello's), a CPU twin of the
//! same name in `src/cpu/`, and one [`Stage`] descriptor here listing its bindings. The GPU layer builds
//! the stage's explicit bind group layouts and pipelines from the descriptor
//! (`gpu::stages`), and `tests/shaders.rs` checks every descriptor against the composed WGSL
//! (reflected with naga): the same bindings, and every uniform/storage struct laid out exactly
//! as its Rust twin in [`crate::encoding::types::LAYOUTS`], field offset by field offset. Adding a stage is: the
//! WGSL file (or files), its twin, a `Stage` constant, a line in [`STAGES`].
//!
//! **Composition.** A WGSL file pulls in shared code with `#import NAME` lines (vello's
//! convention): `shaders/shared/NAME.wgsl`, or one of the generated modules `constants`
//! ([`crate::encoding::constants::wgsl`]), `error_target` (how the error pass writes its target) and `eyes` (how
//! a drawing stage learns which eye it draws, [`EyesPerDraw`]). Each module is composed in once,
//! after the modules it imports.

use crate::encoding::constants;

/// Which pipeline kind a stage makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageKind {
    /// Compute entry points.
    Compute,
    /// A vertex + fragment pipeline (`vs_main`; `fs_main`, and `fs_error` with the error pass,
    /// `fs_position` also writing the surface points).
    Draw,
}

/// How a binding is declared in WGSL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// `var<uniform>`
    Uniform,
    /// `var<storage, read>`
    Storage,
    /// `var<storage, read_write>`
    StorageReadWrite,
}

/// One resource binding of a stage.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    pub group: u32,
    pub binding: u32,
    /// The WGSL variable's name.
    pub name: &'static str,
    pub kind: BindingKind,
}

const fn bind(group: u32, binding: u32, name: &'static str, kind: BindingKind) -> Binding {
    Binding { group, binding, name, kind }
}

use BindingKind::{Storage, StorageReadWrite, Uniform};

/// An entry point and the bindings it uses (by WGSL variable name). A compute entry point gets
/// a pipeline layout of just these (a buffer used as indirect arguments by one dispatch must
/// not be bound as storage to it); a drawing stage's pipeline binds the union of its entry
/// points'. The naga test checks each list against what the entry point really uses.
#[derive(Clone, Copy, Debug)]
pub struct EntryPoint {
    pub name: &'static str,
    pub uses: &'static [&'static str],
    /// The pass's own WGSL file, `shaders/STAGE/NAME.wgsl`, in a stage of several passes (as
    /// vello's); None: in the stage's file.
    pub source: Option<&'static str>,
}

const fn entry(name: &'static str, uses: &'static [&'static str]) -> EntryPoint {
    EntryPoint { name, uses, source: None }
}

/// An entry point in its own file (see [`EntryPoint::source`]).
const fn pass(name: &'static str, uses: &'static [&'static str], source: &'static str) -> EntryPoint {
    EntryPoint { name, uses, source: Some(source) }
}

/// One WGSL file of a stage, and the entry points it holds.
#[derive(Clone, Debug)]
pub struct WgslFile {
    pub path: String,
    pub source: &'static str,
    pub entry_points: Vec<&'static str>,
}

/// A stage: its WGSL file (or one per pass), entry points and bindings.
#[derive(Clone, Copy, Debug)]
pub struct Stage {
    /// The stage's name: its WGSL file is `shaders/NAME.wgsl` (or, one per pass,
    /// `shaders/NAME/ENTRY.wgsl`), its CPU twin `cpu::NAME`.
    pub name: &'static str,
    /// `shaders/NAME.wgsl`; None where each entry point has its own file.
    pub source: Option<&'static str>,
    pub kind: StageKind,
    pub entry_points: &'static [EntryPoint],
    /// Every binding, ordered by group then binding number.
    pub bindings: &'static [Binding],
}

impl Stage {
    /// Its WGSL files: the stage's one, or one per pass.
    pub fn files(&self) -> Vec<WgslFile> {
        match self.source {
            Some(source) => vec![WgslFile {
                path: format!("shaders/{}.wgsl", self.name),
                source,
                entry_points: self.entry_points.iter().map(|e| e.name).collect(),
            }],
            None => self.entry_points.iter().map(|e| self.pass_file(e)).collect(),
        }
    }

    /// The file that holds `entry` (None: the drawing pipeline's, the stage's one file).
    pub fn file_of(&self, entry: Option<&str>) -> WgslFile {
        match (self.source, entry.and_then(|e| self.entry_point(e))) {
            (None, Some(e)) => self.pass_file(e),
            _ => self.files().remove(0),
        }
    }

    fn pass_file(&self, e: &EntryPoint) -> WgslFile {
        let source = e.source.unwrap_or_else(|| panic!("{}: {} has no file of its own", self.name, e.name));
        WgslFile { path: format!("shaders/{}/{}.wgsl", self.name, e.name), source, entry_points: vec![e.name] }
    }

    /// The groups the stage binds (0, 1, … without gaps).
    pub fn group_count(&self) -> u32 {
        self.bindings.iter().map(|b| b.group + 1).max().unwrap_or(0)
    }

    /// The bindings of one group, in binding order.
    pub fn group(&self, group: u32) -> impl Iterator<Item = &Binding> {
        self.bindings.iter().filter(move |b| b.group == group)
    }

    pub fn entry_point(&self, name: &str) -> Option<&EntryPoint> {
        self.entry_points.iter().find(|e| e.name == name)
    }

    /// Whether a pipeline for `entry` (None: the drawing pipeline, all entry points) binds `b`.
    pub fn binds(&self, entry: Option<&str>, b: &Binding) -> bool {
        match entry {
            None => true,
            Some(e) => self.entry_point(e).is_some_and(|e| e.uses.contains(&b.name)),
        }
    }
}

/// The material table the fragment module reads (group 1 of the drawing stages).
/// What the fragment entry points of the drawing stages read: their parameters and group 1.
const SHADING: &[&str] =
    &["params", "materials", "mips", "texels", "lights", "lighting", "environment", "shadow_maps", "shadow_depths"];

/// A stage's bindings: its own, then the material table as group 1.
macro_rules! with_material_table {
    ($($own:expr),* $(,)?) => {
        &[
            $($own,)*
            MATERIAL_TABLE[0],
            MATERIAL_TABLE[1],
            MATERIAL_TABLE[2],
            MATERIAL_TABLE[3],
            MATERIAL_TABLE[4],
            MATERIAL_TABLE[5],
            MATERIAL_TABLE[6],
            MATERIAL_TABLE[7],
        ]
    };
}

/// Group 1 of the stages that shade: the scene's materials and textures, its lights, the
/// frame's lighting, the environment and the frame's shadow maps (src/gpu/scene.rs).
const MATERIAL_TABLE: [Binding; 8] = [
    bind(1, 0, "materials", Storage),
    bind(1, 1, "mips", Storage),
    bind(1, 2, "texels", Storage),
    bind(1, 3, "lights", Storage),
    bind(1, 4, "lighting", Uniform),
    bind(1, 5, "environment", Storage),
    bind(1, 6, "shadow_maps", Storage),
    bind(1, 7, "shadow_depths", Storage),
];

/// The bindings every pass that plans reads and writes (a triangle's corners, its object's level
/// of detail, the pieces and counters it appends to), then `$extra`: a pass's own.
macro_rules! planning {
    ($($extra:literal),* $(,)?) => {
        &["params", "vertices", "indices", "pieces", "counters", "object_edge_scale", $($extra),*]
    };
}

/// What `plan` reads and writes (it plans parts and appends pieces).
const PLANNING: &[&str] = planning!("cut_list", "triangle_edges", "edge_marks_read");

/// What `plan_cuts` reads and writes: it cuts the triangles `plan` listed into parts, which it
/// appends (for `plan_parts`, which plans them) rather than pieces.
const CUTTING: &[&str] = &[
    "params",
    "vertices",
    "indices",
    "counters",
    "object_edge_scale",
    "cut_list",
    "triangle_edges",
    "edge_marks_read",
    "parts",
];

/// The bindings of the passes that plan pieces (`lattice`, `lattice_rows_plan`): they plan pieces,
/// list those whose rows are measured (in `parts`) and append work items, and write small pieces'
/// output in place; `$extra`: a pass's own.
macro_rules! piece_planning {
    ($($extra:literal),*) => {
        planning!("piece_work", "lattice_work", "out_nodes", "out_indices", "parts", $($extra),*)
    };
}

/// `lattice`'s: it also appends the row items.
const PIECE_PLANNING: &[&str] = piece_planning!("row_items");

/// `lattice_rows_plan`'s: it runs over the pieces listed in `parts`.
const ROWS_PLANNING: &[&str] = piece_planning!();

pub const SUBDIVIDE: Stage = Stage {
    name: "subdivide",
    source: None,
    kind: StageKind::Compute,
    entry_points: &[
        pass(
            "active_cuts",
            &["params", "vertices", "indices", "counters", "triangle_edges", "cut_edges"],
            include_str!("../../shaders/subdivide/active_cuts.wgsl"),
        ),
        pass(
            "ring_cuts",
            &["params", "vertices", "indices", "triangle_edges", "cut_edges"],
            include_str!("../../shaders/subdivide/ring_cuts.wgsl"),
        ),
        pass("plan", PLANNING, include_str!("../../shaders/subdivide/plan.wgsl")),
        pass(
            "plan_cuts_args",
            &["counters", "lattice_dispatch", "cut_list"],
            include_str!("../../shaders/subdivide/plan_cuts_args.wgsl"),
        ),
        pass("plan_cuts", CUTTING, include_str!("../../shaders/subdivide/plan_cuts.wgsl")),
        pass(
            "plan_parts_args",
            &["params", "counters", "lattice_dispatch"],
            include_str!("../../shaders/subdivide/plan_parts_args.wgsl"),
        ),
        pass(
            "plan_parts",
            &["params", "vertices", "indices", "pieces", "counters", "object_edge_scale", "parts"],
            include_str!("../../shaders/subdivide/plan_parts.wgsl"),
        ),
        pass(
            "lattice_args",
            &["params", "counters", "lattice_dispatch"],
            include_str!("../../shaders/subdivide/lattice_args.wgsl"),
        ),
        pass("lattice", PIECE_PLANNING, include_str!("../../shaders/subdivide/lattice.wgsl")),
        pass(
            "lattice_rows_args",
            &["params", "counters", "lattice_dispatch"],
            include_str!("../../shaders/subdivide/lattice_rows_args.wgsl"),
        ),
        pass(
            "lattice_rows",
            &["params", "vertices", "indices", "pieces", "counters", "object_edge_scale", "piece_work", "row_items"],
            include_str!("../../shaders/subdivide/lattice_rows.wgsl"),
        ),
        pass("lattice_rows_plan", ROWS_PLANNING, include_str!("../../shaders/subdivide/lattice_rows_plan.wgsl")),
        pass(
            "lattice_work_args",
            &["params", "counters", "lattice_dispatch"],
            include_str!("../../shaders/subdivide/lattice_work_args.wgsl"),
        ),
        pass(
            "lattice_nodes",
            &[
                "params",
                "vertices",
                "indices",
                "pieces",
                "out_nodes",
                "counters",
                "object_edge_scale",
                "piece_work",
                "lattice_work",
            ],
            include_str!("../../shaders/subdivide/lattice_nodes.wgsl"),
        ),
        pass(
            "lattice_triangles",
            &["params", "pieces", "out_nodes", "counters", "out_indices", "piece_work", "lattice_work"],
            include_str!("../../shaders/subdivide/lattice_triangles.wgsl"),
        ),
        pass("finalize", &["params", "counters", "draw_args"], include_str!("../../shaders/subdivide/finalize.wgsl")),
    ],
    bindings: &[
        bind(0, 0, "params", Storage),
        bind(0, 1, "vertices", Storage),
        bind(0, 2, "indices", Storage),
        bind(0, 3, "pieces", StorageReadWrite),
        bind(0, 4, "out_nodes", StorageReadWrite),
        bind(0, 5, "counters", StorageReadWrite),
        bind(0, 6, "draw_args", StorageReadWrite),
        bind(0, 7, "lattice_dispatch", StorageReadWrite),
        bind(0, 8, "object_edge_scale", Storage),
        bind(0, 9, "cut_list", StorageReadWrite),
        bind(0, 10, "out_indices", StorageReadWrite),
        bind(0, 11, "triangle_edges", Storage),
        bind(0, 12, "cut_edges", StorageReadWrite),
        bind(0, 13, "edge_marks_read", Storage),
        bind(0, 14, "parts", StorageReadWrite),
        bind(0, 15, "piece_work", StorageReadWrite),
        bind(0, 16, "lattice_work", StorageReadWrite),
        bind(0, 17, "row_items", StorageReadWrite),
    ],
};

pub const RASTER: Stage = Stage {
    name: "raster",
    source: Some(include_str!("../../shaders/raster.wgsl")),
    kind: StageKind::Draw,
    entry_points: &[
        entry("vs_main", &["params"]),
        entry("fs_main", SHADING),
        entry("fs_coverage", SHADING),
        entry("fs_error", SHADING),
        entry("fs_position", SHADING),
        entry("vs_background", &[]),
        entry("fs_background", &["params", "lighting", "environment"]),
    ],
    bindings: with_material_table![bind(0, 0, "params", Uniform),],
};

pub const SLIT: Stage = Stage {
    name: "slit",
    source: Some(include_str!("../../shaders/slit.wgsl")),
    kind: StageKind::Draw,
    entry_points: &[
        entry("vs_main", &["params", "cameras"]),
        entry("fs_main", SHADING),
        entry("fs_coverage", SHADING),
        entry("fs_error", SHADING),
        entry("fs_position", SHADING),
        entry("vs_background", &[]),
        entry("fs_background", &["params", "lighting", "environment"]),
    ],
    bindings: with_material_table![bind(0, 0, "params", Uniform), bind(0, 1, "cameras", Storage),],
};

pub const TRACE: Stage = Stage {
    name: "trace",
    source: Some(include_str!("../../shaders/trace.wgsl")),
    kind: StageKind::Compute,
    entry_points: &[entry(
        "trace",
        &[
            "params",
            "vertices",
            "indices",
            "bvh_nodes",
            "bvh_levels",
            "out_color",
            "out_error",
            "out_object",
            "out_distance",
            "counts",
            "materials",
            "mips",
            "texels",
            "lights",
            "lighting",
            "environment",
            "shadow_maps",
            "shadow_depths",
        ],
    )],
    bindings: with_material_table![
        bind(0, 0, "params", Uniform),
        bind(0, 1, "vertices", Storage),
        bind(0, 2, "indices", Storage),
        bind(0, 3, "bvh_nodes", Storage),
        bind(0, 4, "bvh_levels", Storage),
        bind(0, 5, "out_color", StorageReadWrite),
        bind(0, 6, "out_error", StorageReadWrite),
        bind(0, 7, "out_object", StorageReadWrite),
        bind(0, 8, "out_distance", StorageReadWrite),
        bind(0, 9, "counts", StorageReadWrite),
    ],
};

pub const SHADOW: Stage = Stage {
    name: "shadow",
    source: Some(include_str!("../../shaders/shadow.wgsl")),
    kind: StageKind::Draw,
    entry_points: &[entry("vs_main", &["params"]), entry("fs_mask", &["materials", "mips", "texels", "lighting"])],
    bindings: with_material_table![bind(0, 0, "params", Uniform),],
};

pub const SKIN: Stage = Stage {
    name: "skin",
    source: Some(include_str!("../../shaders/skin.wgsl")),
    kind: StageKind::Compute,
    entry_points: &[entry(
        "skin",
        &["params", "sources", "deltas", "instances", "joints", "morph_weights", "vertices"],
    )],
    bindings: &[
        bind(0, 0, "params", Uniform),
        bind(0, 1, "sources", Storage),
        bind(0, 2, "deltas", Storage),
        bind(0, 3, "instances", Storage),
        bind(0, 4, "joints", Storage),
        bind(0, 5, "morph_weights", Storage),
        bind(0, 6, "vertices", StorageReadWrite),
    ],
};

pub const PROJECT_POINTS: Stage = Stage {
    name: "project_points",
    source: Some(include_str!("../../shaders/project_points.wgsl")),
    kind: StageKind::Compute,
    entry_points: &[entry("project_points", &["params", "points", "pixels"])],
    bindings: &[bind(0, 0, "params", Uniform), bind(0, 1, "points", Storage), bind(0, 2, "pixels", StorageReadWrite)],
};

pub const DISPLAY: Stage = Stage {
    name: "display",
    source: Some(include_str!("../../shaders/display.wgsl")),
    kind: StageKind::Draw,
    entry_points: &[entry("vs_main", &[]), entry("fs_main", &["params", "texels", "overlay"])],
    bindings: &[bind(0, 0, "params", Uniform), bind(0, 1, "texels", Storage), bind(0, 2, "overlay", Storage)],
};

pub const REDUCE_ERROR: Stage = Stage {
    name: "reduce_error",
    source: Some(include_str!("../../shaders/reduce_error.wgsl")),
    kind: StageKind::Compute,
    entry_points: &[
        entry("accumulate", &["params", "errors", "histogram", "partials", "totals"]),
        entry("finish", &["params", "histogram", "partials", "totals", "result"]),
    ],
    bindings: &[
        bind(0, 0, "params", Uniform),
        bind(0, 1, "errors", Storage),
        bind(0, 2, "histogram", StorageReadWrite),
        bind(0, 3, "partials", StorageReadWrite),
        bind(0, 4, "totals", StorageReadWrite),
        bind(0, 5, "result", StorageReadWrite),
    ],
};

/// The registry: every stage. The naga test validates and reflects each one composed.
pub const STAGES: &[Stage] = &[SKIN, SUBDIVIDE, RASTER, SLIT, TRACE, SHADOW, PROJECT_POINTS, REDUCE_ERROR, DISPLAY];

/// The shared WGSL modules in `shaders/shared/`, by import name.
pub const SHARED: &[(&str, &str)] = &[
    ("projection", include_str!("../../shaders/shared/projection.wgsl")),
    ("projection_sphere", include_str!("../../shaders/shared/projection_sphere.wgsl")),
    ("projection_sphere_off", include_str!("../../shaders/shared/projection_sphere_off.wgsl")),
    ("projection_fisheye", include_str!("../../shaders/shared/projection_fisheye.wgsl")),
    ("projection_fisheye_off", include_str!("../../shaders/shared/projection_fisheye_off.wgsl")),
    ("projection_head", include_str!("../../shaders/shared/projection_head.wgsl")),
    ("projection_head_off", include_str!("../../shaders/shared/projection_head_off.wgsl")),
    ("projection_cubemap", include_str!("../../shaders/shared/projection_cubemap.wgsl")),
    ("projection_cubemap_off", include_str!("../../shaders/shared/projection_cubemap_off.wgsl")),
    ("projection_cave", include_str!("../../shaders/shared/projection_cave.wgsl")),
    ("projection_cave_off", include_str!("../../shaders/shared/projection_cave_off.wgsl")),
    ("scene", include_str!("../../shaders/shared/scene.wgsl")),
    ("subdivide_types", include_str!("../../shaders/shared/subdivide_types.wgsl")),
    ("subdivide_bindings", include_str!("../../shaders/shared/subdivide_bindings.wgsl")),
    ("subdivide_state", include_str!("../../shaders/shared/subdivide_state.wgsl")),
    ("subdivide_spacing", include_str!("../../shaders/shared/subdivide_spacing.wgsl")),
    ("subdivide_spacing_off", include_str!("../../shaders/shared/subdivide_spacing_off.wgsl")),
    ("subdivide_edges", include_str!("../../shaders/shared/subdivide_edges.wgsl")),
    ("subdivide_frame_cuts", include_str!("../../shaders/shared/subdivide_frame_cuts.wgsl")),
    ("subdivide_axis", include_str!("../../shaders/shared/subdivide_axis.wgsl")),
    ("subdivide_dispatch", include_str!("../../shaders/shared/subdivide_dispatch.wgsl")),
    ("subdivide_lattice", include_str!("../../shaders/shared/subdivide_lattice.wgsl")),
    ("subdivide_bands", include_str!("../../shaders/shared/subdivide_bands.wgsl")),
    ("subdivide_rows", include_str!("../../shaders/shared/subdivide_rows.wgsl")),
    ("subdivide_rows_off", include_str!("../../shaders/shared/subdivide_rows_off.wgsl")),
    ("subdivide_work", include_str!("../../shaders/shared/subdivide_work.wgsl")),
    ("subdivide_in_place", include_str!("../../shaders/shared/subdivide_in_place.wgsl")),
    ("surface_bindings", include_str!("../../shaders/shared/surface_bindings.wgsl")),
    ("texture", include_str!("../../shaders/shared/texture.wgsl")),
    ("brdf", include_str!("../../shaders/shared/brdf.wgsl")),
    ("ibl", include_str!("../../shaders/shared/ibl.wgsl")),
    ("pixel_error", include_str!("../../shaders/shared/pixel_error.wgsl")),
    ("surface", include_str!("../../shaders/shared/surface.wgsl")),
    ("fragment", include_str!("../../shaders/shared/fragment.wgsl")),
];

/// A shared module, and the stand-in a pipeline that never runs its code may be composed with in
/// its place: the same functions, doing nothing (lavapipe builds a pipeline, and may run it,
/// slower for code it never takes: a constant `override` does not remove it).
pub type StandIn = (&'static str, &'static str);

/// Every stand-in (the naga test validates each file composed with each one).
pub const STAND_INS: &[StandIn] = &[ROWS_OFF, SPACING_OFF, SPHERE_OFF, FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF];

/// `subdivide_rows` left out: the `lattice` pipeline of the frames that never draw rows.
pub const ROWS_OFF: StandIn = ("subdivide_rows", "subdivide_rows_off");

/// `subdivide_spacing` left out: the subdivide stage's pipelines for the split rules that space
/// nodes evenly (all but the error split: `cpu::subdivide::spacing`).
pub const SPACING_OFF: StandIn = ("subdivide_spacing", "subdivide_spacing_off");

/// `projection_sphere` left out: the subdivide stage's pipelines for the cylinder.
pub const SPHERE_OFF: StandIn = ("projection_sphere", "projection_sphere_off");

/// `projection_fisheye` left out: the subdivide stage's pipelines for the other panoramas.
pub const FISHEYE_OFF: StandIn = ("projection_fisheye", "projection_fisheye_off");

/// `projection_head` left out: the subdivide stage's pipelines for frames without a tracked head.
pub const HEAD_OFF: StandIn = ("projection_head", "projection_head_off");

/// `projection_cubemap` left out: every subdivide stage's pipeline (it measures a cubemap on the
/// sphere, `Projection::measured`).
pub const CUBEMAP_OFF: StandIn = ("projection_cubemap", "projection_cubemap_off");

/// `projection_cave` left out: every subdivide stage's pipeline (a CAVE wall is drawn without
/// subdivision).
pub const CAVE_OFF: StandIn = ("projection_cave", "projection_cave_off");

/// How the error target is written: as f32 (R32Float) or as its bits (R32Uint), for adapters
/// that cannot render to R32Float.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorTarget {
    Float,
    UintBits,
}

impl ErrorTarget {
    /// The generated module `error_target`: the target's WGSL type and its encoder.
    pub fn wgsl(self) -> &'static str {
        match self {
            ErrorTarget::Float => "alias ErrorTarget = f32;\nfn encode_error(e: f32) -> ErrorTarget { return e; }\n",
            ErrorTarget::UintBits => {
                "alias ErrorTarget = u32;\nfn encode_error(e: f32) -> ErrorTarget { return bitcast<u32>(e); }\n"
            }
        }
    }
}

/// How the raster stage draws the two eyes: both in one draw (multiview: each eye is a view,
/// a layer of the 2-layer targets, and `@builtin(view_index)` tells the shader which), or one
/// render pass per eye with a pipeline built for that eye (the WGSL `override EYE`), on adapters
/// without multiview.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EyesPerDraw {
    Both,
    One,
}

impl EyesPerDraw {
    /// The generated module `eyes`: `EyeIn`, a vertex-stage input, and `eye_index(EyeIn)`, the
    /// eye drawn (0 left, 1 right).
    pub fn wgsl(self) -> &'static str {
        match self {
            EyesPerDraw::Both => {
                "struct EyeIn { @builtin(view_index) view: u32, }\nfn eye_index(e: EyeIn) -> u32 { return e.view; }\n"
            }
            EyesPerDraw::One => {
                "override EYE: u32 = 0u;\nstruct EyeIn { @builtin(instance_index) instance: u32, }\n\
                 fn eye_index(e: EyeIn) -> u32 { return EYE; }\n"
            }
        }
    }
}

/// What the generated modules depend on: the adapter's capabilities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShaderOptions {
    pub error_target: ErrorTarget,
    pub eyes: EyesPerDraw,
}

impl ShaderOptions {
    /// Every combination (the naga test validates each stage under all of them).
    pub const ALL: [ShaderOptions; 4] = [
        ShaderOptions { error_target: ErrorTarget::Float, eyes: EyesPerDraw::Both },
        ShaderOptions { error_target: ErrorTarget::Float, eyes: EyesPerDraw::One },
        ShaderOptions { error_target: ErrorTarget::UintBits, eyes: EyesPerDraw::Both },
        ShaderOptions { error_target: ErrorTarget::UintBits, eyes: EyesPerDraw::One },
    ];
}

/// The source of an importable module (its stand-in's where one is given), or None for an unknown
/// name.
fn module_source(name: &str, options: ShaderOptions, stand_ins: &[StandIn]) -> Option<String> {
    let name = stand_ins.iter().find(|(module, _)| *module == name).map_or(name, |(_, stand_in)| *stand_in);
    match name {
        "constants" => Some(constants::wgsl()),
        "error_target" => Some(options.error_target.wgsl().to_string()),
        "eyes" => Some(options.eyes.wgsl().to_string()),
        _ => SHARED.iter().find(|(n, _)| *n == name).map(|(_, s)| s.to_string()),
    }
}

/// The names a source imports, in order.
pub fn imports(source: &str) -> Vec<&str> {
    source.lines().filter_map(|l| l.trim().strip_prefix("#import ")).map(str::trim).collect()
}

/// The full WGSL of one of a stage's files: its imports (recursively, each once, dependencies
/// first), then the file with its `#import` lines commented out.
pub fn compose(file: &WgslFile, options: ShaderOptions) -> String {
    compose_with(file, options, &[])
}

/// The same, with stand-ins composed in place of the modules they stand for.
pub fn compose_with(file: &WgslFile, options: ShaderOptions, stand_ins: &[StandIn]) -> String {
    type Context<'a> = (ShaderOptions, &'a [StandIn]);
    fn add(name: &str, source: &str, context: Context, done: &mut Vec<String>, out: &mut String) {
        for dep in imports(source) {
            if done.iter().any(|d| d == dep) {
                continue;
            }
            done.push(dep.to_string());
            let Some(dep_source) = module_source(dep, context.0, context.1) else {
                panic!("{name}: `#import {dep}` names no module in shaders/shared/ or the generated ones")
            };
            add(dep, &dep_source, context, done, out);
        }
        let body: Vec<String> = source
            .lines()
            .map(|l| if l.trim().starts_with("#import ") { format!("// {l}") } else { l.to_string() })
            .collect();
        *out += &format!("// ---- {name} ----\n{}\n", body.join("\n"));
    }
    let mut out = String::new();
    let mut done = Vec::new();
    add(&file.path, file.source, (options, stand_ins), &mut done, &mut out);
    out
}
