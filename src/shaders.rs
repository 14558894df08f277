//! WGSL sources and their composition. One file per stage in `shaders/`; the projection shared
//! by several stages lives in `shaders/projection.wgsl` and is composed in front of each stage
//! that projects when the module is loaded.

/// The shared projection module (seed 002 eq. 1–4).
pub const PROJECTION: &str = include_str!("../shaders/projection.wgsl");

/// A stage's WGSL file.
#[derive(Clone, Copy, Debug)]
pub struct Stage {
    pub name: &'static str,
    pub file: &'static str,
    pub source: &'static str,
    pub needs_projection: bool,
}

pub const SUBDIVIDE: Stage = Stage {
    name: "subdivide",
    file: "shaders/subdivide.wgsl",
    source: include_str!("../shaders/subdivide.wgsl"),
    needs_projection: true,
};
pub const RASTER: Stage = Stage {
    name: "raster",
    file: "shaders/raster.wgsl",
    source: include_str!("../shaders/raster.wgsl"),
    needs_projection: true,
};
pub const PROJECT_POINTS: Stage = Stage {
    name: "project_points",
    file: "shaders/project_points.wgsl",
    source: include_str!("../shaders/project_points.wgsl"),
    needs_projection: true,
};

/// Every stage; the naga test validates each one composed.
pub const STAGES: &[Stage] = &[SUBDIVIDE, RASTER, PROJECT_POINTS];

/// The full WGSL source of a stage, with the modules it needs composed in front.
pub fn compose(stage: &Stage) -> String {
    if stage.needs_projection {
        format!("{PROJECTION}\n// ---- {} ----\n{}", stage.file, stage.source)
    } else {
        stage.source.to_string()
    }
}

pub fn load(device: &wgpu::Device, stage: &Stage) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(stage.name),
        source: wgpu::ShaderSource::Wgsl(compose(stage).into()),
    })
}
