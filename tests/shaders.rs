//! Every WGSL file in shaders/ is validated with naga: the shared projection module alone, and
//! each stage as it is loaded (with its modules composed in front).

use twister::shaders::{compose, ErrorTarget, Module, STAGES};

fn validate(name: &str, source: &str) {
    let module = match naga::front::wgsl::parse_str(source) {
        Ok(m) => m,
        Err(e) => panic!("{name}: parse error\n{}", e.emit_to_string_with_path(source, name)),
    };
    let mut validator =
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all());
    if let Err(e) = validator.validate(&module) {
        panic!("{name}: validation error\n{}", e.emit_to_string_with_path(source, name));
    }
}

#[test]
fn every_wgsl_file_validates_with_naga() {
    validate(Module::Projection.file(), Module::Projection.source());
    // The fragment module alone, with a stub of the `params` its contract asks stages to declare.
    let stub = "struct StubParams { projection: Projection, eye_sign: f32, ambient: f32 }\n@group(0) @binding(0) var<uniform> params: StubParams;";
    validate(
        Module::Fragment.file(),
        &format!("{}\n{stub}\n{}", Module::Projection.source(), Module::Fragment.source()),
    );
    // Each stage with its modules, in both error-target variants.
    for stage in STAGES {
        for target in [ErrorTarget::Float, ErrorTarget::UintBits] {
            validate(&format!("{} ({target:?})", stage.file), &compose(stage, target));
        }
    }
    // Every file in shaders/ is covered: the projection module or a registered stage.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = format!("shaders/{}", entry.unwrap().file_name().to_string_lossy());
        assert!(
            [Module::Projection, Module::Fragment].iter().any(|m| m.file() == name)
                || STAGES.iter().any(|s| s.file == name),
            "{name} is not registered in twister::shaders::STAGES"
        );
    }
}

#[test]
fn uniform_struct_sizes_match_wgsl() {
    use twister::gpu_types::*;
    // Sizes naga computes for the WGSL structs must equal the Rust twins'.
    let size_of = |stage: &twister::shaders::Stage, name: &str| {
        let module = naga::front::wgsl::parse_str(&compose(stage, ErrorTarget::Float)).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (h, _) =
            module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("{name}"));
        layouter[h].size as usize
    };
    let (subdivide, raster) = (&twister::shaders::SUBDIVIDE, &twister::shaders::RASTER);
    assert_eq!(size_of(subdivide, "SceneVertex"), std::mem::size_of::<SceneVertex>());
    assert_eq!(size_of(subdivide, "DrawVertex"), std::mem::size_of::<DrawVertex>());
    assert_eq!(size_of(subdivide, "Projection"), std::mem::size_of::<ProjectionUniform>());
    assert_eq!(size_of(subdivide, "SubdivideParams"), std::mem::size_of::<SubdivideParams>());
    assert_eq!(size_of(subdivide, "Counters"), std::mem::size_of::<SubdivideCounters>());
    assert_eq!(size_of(subdivide, "DrawIndirectArgs"), std::mem::size_of::<DrawIndirectArgs>());
    assert_eq!(size_of(raster, "RasterParams"), std::mem::size_of::<RasterParams>());
    let reduce = &twister::shaders::REDUCE_ERROR;
    assert_eq!(size_of(reduce, "ReduceParams"), std::mem::size_of::<twister::reduce::ReduceParams>());
    assert_eq!(size_of(reduce, "ErrorStats"), std::mem::size_of::<twister::reduce::ErrorStats>());
}
