//! WGSL sources and their composition. One file per stage in `shaders/`; the projection shared
//! by several stages lives in `shaders/projection.wgsl` and is composed in front of each stage
//! that projects when the module is loaded.

/// The shared projection module (seed 002 eq. 1–4).
pub const PROJECTION: &str = include_str!("../shaders/projection.wgsl");
/// The shared fragment module (shading, display-position error, output targets).
pub const FRAGMENT: &str = include_str!("../shaders/fragment.wgsl");

/// Shared modules a stage can need, composed in this order in front of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Module {
    Projection,
    Fragment,
}

impl Module {
    pub fn file(self) -> &'static str {
        match self {
            Module::Projection => "shaders/projection.wgsl",
            Module::Fragment => "shaders/fragment.wgsl",
        }
    }

    pub fn source(self) -> &'static str {
        match self {
            Module::Projection => PROJECTION,
            Module::Fragment => FRAGMENT,
        }
    }
}

/// How the error target is written: as f32 (R32Float) or as its bits (R32Uint), for adapters
/// that cannot render to R32Float.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorTarget {
    Float,
    UintBits,
}

impl ErrorTarget {
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            ErrorTarget::Float => wgpu::TextureFormat::R32Float,
            ErrorTarget::UintBits => wgpu::TextureFormat::R32Uint,
        }
    }
}

/// A stage's WGSL file.
#[derive(Clone, Copy, Debug)]
pub struct Stage {
    pub name: &'static str,
    pub file: &'static str,
    pub source: &'static str,
    /// Shared modules composed in front, in order.
    pub modules: &'static [Module],
}

pub const SUBDIVIDE: Stage = Stage {
    name: "subdivide",
    file: "shaders/subdivide.wgsl",
    source: include_str!("../shaders/subdivide.wgsl"),
    modules: &[Module::Projection],
};
pub const RASTER: Stage = Stage {
    name: "raster",
    file: "shaders/raster.wgsl",
    source: include_str!("../shaders/raster.wgsl"),
    modules: &[Module::Projection, Module::Fragment],
};
pub const PROJECT_POINTS: Stage = Stage {
    name: "project_points",
    file: "shaders/project_points.wgsl",
    source: include_str!("../shaders/project_points.wgsl"),
    modules: &[Module::Projection],
};

pub const SLIT: Stage = Stage {
    name: "slit",
    file: "shaders/slit.wgsl",
    source: include_str!("../shaders/slit.wgsl"),
    modules: &[Module::Projection, Module::Fragment],
};
pub const REDUCE_ERROR: Stage = Stage {
    name: "reduce_error",
    file: "shaders/reduce_error.wgsl",
    source: include_str!("../shaders/reduce_error.wgsl"),
    modules: &[],
};

/// Every stage; the naga test validates each one composed.
pub const STAGES: &[Stage] = &[SUBDIVIDE, RASTER, SLIT, PROJECT_POINTS, REDUCE_ERROR];

/// The full WGSL source of a stage, with the modules it needs composed in front.
pub fn compose(stage: &Stage, error_target: ErrorTarget) -> String {
    let mut out = String::new();
    for m in stage.modules {
        let mut src = m.source().to_string();
        if *m == Module::Fragment && error_target == ErrorTarget::UintBits {
            src = src
                .lines()
                .map(|l| {
                    if l.ends_with("// ERROR_TARGET") {
                        "alias ErrorTarget = u32; // ERROR_TARGET".to_string()
                    } else if l.ends_with("// ERROR_ENCODE") {
                        "fn encode_error(e: f32) -> ErrorTarget { return bitcast<u32>(e); } // ERROR_ENCODE".to_string()
                    } else {
                        l.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
        }
        out += &format!("// ---- {} ----\n{src}\n", m.file());
    }
    out + &format!("// ---- {} ----\n{}", stage.file, stage.source)
}

pub fn load(device: &wgpu::Device, stage: &Stage, error_target: ErrorTarget) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(stage.name),
        source: wgpu::ShaderSource::Wgsl(compose(stage, error_target).into()),
    })
}
