//! The WGSL side against the Rust side, with naga: every stage of the registry composes and
//! validates (both error-target variants); every file in shaders/ is used; each stage's
//! declared bindings are exactly its descriptor's; and every struct a stage binds is laid out
//! exactly as its Rust twin in `encoding::types::LAYOUTS`, field offset by field offset.

use std::collections::BTreeSet;

use naga::{AddressSpace, StorageAccess, TypeInner};
use twister::encoding::types::{StructLayout, LAYOUTS};
use twister::shader::{compose, compose_with, imports, BindingKind, ShaderOptions, Stage, SHARED, STAGES, STAND_INS};

fn parse(name: &str, source: &str) -> naga::Module {
    parse_with_info(name, source).0
}

fn parse_with_info(name: &str, source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = match naga::front::wgsl::parse_str(source) {
        Ok(m) => m,
        Err(e) => panic!("{name}: parse error\n{}", e.emit_to_string_with_path(source, name)),
    };
    let mut validator =
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all());
    match validator.validate(&module) {
        Ok(info) => (module, info),
        Err(e) => panic!("{name}: validation error\n{}", e.emit_to_string_with_path(source, name)),
    }
}

#[test]
fn every_stage_composes_and_validates_and_every_wgsl_file_is_used() {
    let mut used = BTreeSet::new();
    for file in STAGES.iter().flat_map(|stage| stage.files()) {
        for options in ShaderOptions::ALL {
            parse(&format!("{} ({options:?})", file.path), &compose(&file, options));
        }
        used.insert(file.path.clone());
        // Shared modules it reaches (and their stand-ins, with which it must compose too).
        let mut pending: Vec<&str> = imports(file.source);
        for stand_in in STAND_INS {
            let with = compose_with(&file, ShaderOptions::ALL[0], &[*stand_in]);
            if with != compose(&file, ShaderOptions::ALL[0]) {
                parse(&format!("{} (with {})", file.path, stand_in.1), &with);
                pending.push(stand_in.1);
            }
        }
        while let Some(name) = pending.pop() {
            if let Some((_, src)) = SHARED.iter().find(|(n, _)| *n == name) {
                if used.insert(format!("shaders/shared/{name}.wgsl")) {
                    pending.extend(imports(src));
                }
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["shaders", "shaders/shared", "shaders/subdivide"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let entry = entry.unwrap();
            if entry.path().extension().is_some_and(|e| e == "wgsl") {
                let name = format!("{dir}/{}", entry.file_name().to_string_lossy());
                assert!(used.contains(&name), "{name} is neither a registered stage nor imported by one");
            }
        }
    }
}

/// The bindings a module declares: (group, binding, name, kind).
fn declared_bindings(module: &naga::Module) -> BTreeSet<(u32, u32, String, String)> {
    module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            let b = g.binding.as_ref()?;
            let kind = match g.space {
                AddressSpace::Uniform => "Uniform",
                AddressSpace::Storage { access } if access.contains(StorageAccess::STORE) => "StorageReadWrite",
                AddressSpace::Storage { .. } => "Storage",
                other => panic!("unexpected address space {other:?}"),
            };
            Some((b.group, b.binding, g.name.clone().unwrap_or_default(), kind.to_string()))
        })
        .collect()
}

fn descriptor_bindings(stage: &Stage) -> BTreeSet<(u32, u32, String, String)> {
    stage
        .bindings
        .iter()
        .map(|b| {
            let kind = match b.kind {
                BindingKind::Uniform => "Uniform",
                BindingKind::Storage => "Storage",
                BindingKind::StorageReadWrite => "StorageReadWrite",
            };
            (b.group, b.binding, b.name.to_string(), kind.to_string())
        })
        .collect()
}

#[test]
fn each_stage_declares_exactly_the_bindings_and_entry_points_of_its_descriptor() {
    for (stage, file) in STAGES.iter().flat_map(|stage| stage.files().into_iter().map(move |f| (stage, f))) {
        let (module, info) = parse_with_info(&file.path, &compose(&file, ShaderOptions::ALL[0]));
        assert_eq!(declared_bindings(&module), descriptor_bindings(stage), "{}: bindings", file.path);
        let entries: BTreeSet<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
        let wanted: BTreeSet<&str> = file.entry_points.iter().copied().collect();
        assert_eq!(entries, wanted, "{}: entry points", file.path);
        // Each entry point uses exactly the bindings its descriptor lists.
        for (k, ep) in module.entry_points.iter().enumerate() {
            let function = info.get_entry_point(k);
            let used: BTreeSet<String> = module
                .global_variables
                .iter()
                .filter(|(h, g)| g.binding.is_some() && !function[*h].is_empty())
                .map(|(_, g)| g.name.clone().unwrap_or_default())
                .collect();
            let listed: BTreeSet<String> =
                stage.entry_point(&ep.name).unwrap().uses.iter().map(|n| n.to_string()).collect();
            assert_eq!(used, listed, "{} {}: bindings used", stage.name, ep.name);
        }
        // Groups have no gaps (the pipeline layout lists them in order).
        for g in 0..stage.group_count() {
            assert!(stage.group(g).next().is_some(), "{}: group {g} is empty", stage.name);
        }
    }
}

/// Every struct type reachable from the module's bound variables.
fn bound_structs(module: &naga::Module) -> BTreeSet<naga::Handle<naga::Type>> {
    fn visit(module: &naga::Module, ty: naga::Handle<naga::Type>, out: &mut BTreeSet<naga::Handle<naga::Type>>) {
        match &module.types[ty].inner {
            TypeInner::Struct { members, .. } if out.insert(ty) => {
                for m in members {
                    visit(module, m.ty, out);
                }
            }
            TypeInner::Array { base, .. } | TypeInner::BindingArray { base, .. } => visit(module, *base, out),
            _ => {}
        }
    }
    let mut out = BTreeSet::new();
    for (_, g) in module.global_variables.iter().filter(|(_, g)| g.binding.is_some()) {
        visit(module, g.ty, &mut out);
    }
    out
}

/// Differences between a WGSL struct (as naga lays it out) and a Rust layout.
fn layout_mismatches(module: &naga::Module, ty: naga::Handle<naga::Type>, rust: &StructLayout) -> Vec<String> {
    let TypeInner::Struct { members, span } = &module.types[ty].inner else { panic!("not a struct") };
    let mut out = Vec::new();
    if *span as usize != rust.size {
        out.push(format!("{}: WGSL size {span}, Rust {} size {}", rust.wgsl_name, rust.rust_name, rust.size));
    }
    let wgsl: Vec<(String, usize)> =
        members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize)).collect();
    let rust_fields: Vec<(String, usize)> = rust.fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
    if wgsl != rust_fields {
        out.push(format!("{}: WGSL fields {wgsl:?} but Rust {} has {rust_fields:?}", rust.wgsl_name, rust.rust_name));
    }
    out
}

#[test]
fn every_bound_struct_has_the_field_offsets_of_its_rust_twin() {
    let mut checked = BTreeSet::new();
    for (stage, file) in STAGES.iter().flat_map(|stage| stage.files().into_iter().map(move |f| (stage, f))) {
        let module = parse(&file.path, &compose(&file, ShaderOptions::ALL[0]));
        for ty in bound_structs(&module) {
            let name = module.types[ty].name.clone().unwrap_or_default();
            let rust = LAYOUTS
                .iter()
                .find(|l| l.wgsl_name == name)
                .unwrap_or_else(|| panic!("{}: struct {name} is bound but has no Rust twin in LAYOUTS", stage.name));
            let mismatches = layout_mismatches(&module, ty, rust);
            assert!(mismatches.is_empty(), "{}: {}", stage.name, mismatches.join("; "));
            checked.insert(name);
        }
    }
    // Every Rust layout is used by some stage (no stale twin).
    for l in LAYOUTS {
        assert!(checked.contains(l.wgsl_name), "LAYOUTS lists {} but no stage binds it", l.wgsl_name);
    }
}

#[test]
fn the_layout_check_catches_a_moved_field() {
    let module =
        parse("lattice", &compose(&twister::shader::SUBDIVIDE.file_of(Some("lattice")), ShaderOptions::ALL[0]));
    let (ty, _) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some("Counters")).unwrap();
    let good = LAYOUTS.iter().find(|l| l.wgsl_name == "Counters").unwrap();
    assert!(layout_mismatches(&module, ty, good).is_empty());
    let moved =
        StructLayout { fields: &[("pieces", 0), ("triangles", 8), ("max_edge_bits", 4), ("_pad", 12)], ..*good };
    assert_eq!(layout_mismatches(&module, ty, &moved).len(), 1);
    let resized = StructLayout { size: 20, ..*good };
    assert_eq!(layout_mismatches(&module, ty, &resized).len(), 1);
}

#[test]
fn generated_constants_are_what_the_rust_side_says() {
    use twister::encoding::constants::{all, Value};
    let module =
        parse("lattice", &compose(&twister::shader::SUBDIVIDE.file_of(Some("lattice")), ShaderOptions::ALL[0]));
    for (name, value) in all() {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("constant {name} missing from the composed WGSL"));
        let literal = match module.global_expressions[c.init] {
            naga::Expression::Literal(l) => l,
            ref other => panic!("{name}: {other:?}"),
        };
        match (value, literal) {
            (Value::U32(v), naga::Literal::U32(w)) => assert_eq!(v, w, "{name}"),
            (Value::F32(v), naga::Literal::F32(w)) => assert_eq!(v.to_bits(), w.to_bits(), "{name}"),
            (v, l) => panic!("{name}: Rust {v:?}, WGSL {l:?}"),
        }
    }
}

#[test]
fn shared_modules_declare_no_entry_points_and_only_binding_modules_declare_bindings() {
    for (name, source) in SHARED {
        let code: Vec<&str> = source.lines().map(str::trim).filter(|l| !l.starts_with("//")).collect();
        let entry =
            code.iter().find(|l| l.starts_with("@vertex") || l.starts_with("@fragment") || l.starts_with("@compute"));
        assert!(entry.is_none(), "shaders/shared/{name}.wgsl declares an entry point: each stage file owns its own");
        let binding = code.iter().find(|l| l.contains("@group("));
        assert!(
            name.ends_with("_bindings") || binding.is_none(),
            "shaders/shared/{name}.wgsl declares a binding ({}): bindings live in *_bindings modules",
            binding.unwrap_or(&"")
        );
    }
}

#[test]
fn the_subdivisions_recordings_name_its_entry_points_and_bindings() {
    use twister::encoding::recording::Command;
    use twister::encoding::subdivide::{
        active_cuts, one_submission, pass_run, timed_passes, PassTiming, Passes, PASS_GROUPS, TIMED_PASSES,
    };
    use twister::shader::SUBDIVIDE;
    let entries: Vec<&str> = SUBDIVIDE.entry_points.iter().map(|e| e.name).collect();
    // A handle is bound when some binding of the stage binds its buffer.
    let bound = |buffer: twister::encoding::recording::SubdivideBuffer| {
        SUBDIVIDE
            .bindings
            .iter()
            .any(|b| twister::encoding::recording::SubdivideBuffer::bound_as(b.name) == Some(buffer))
    };
    let all = Passes { rows: true };
    let usual = one_submission(1000, all, PassTiming::EachPass);
    // The usual frame of the sphere under an adaptive rule dispatches every entry point, in the
    // order the passes depend on.
    let order: Vec<&str> = usual.entries().collect();
    assert_eq!(order, entries);
    let expected = [
        ["active_cuts", "ring_cuts", "plan", "plan_cuts_args", "plan_cuts", "plan_parts_args", "plan_parts"].as_slice(),
        &["lattice_args", "lattice", "lattice_rows_args", "lattice_rows", "lattice_rows_plan"],
        &["lattice_work_args", "lattice_nodes", "lattice_triangles", "finalize"],
    ];
    assert_eq!(order, expected.concat());
    // The frames without rows (the cylinder's, `vertex`'s) leave out their passes.
    let cylinder: Vec<&str> = one_submission(7, Passes { rows: false }, PassTiming::Untimed).entries().collect();
    let optional = ["lattice_rows_args", "lattice_rows", "lattice_rows_plan"];
    let always: Vec<&str> = order.iter().copied().filter(|e| !optional.contains(e)).collect();
    assert_eq!(cylinder, always);
    // Timed: each main entry point's pass apart (its setup pass and `finalize` with a neighbour),
    // or the three groups; each pass at the next pair of queries, within the query set.
    let some = [Passes { rows: false }, all];
    for p in some {
        let main: Vec<&str> = one_submission(7, p, PassTiming::Untimed)
            .entries()
            .filter(|e| !e.ends_with("_args") && *e != "finalize")
            .collect();
        for (timing, labels) in [(PassTiming::EachPass, main), (PassTiming::Grouped, PASS_GROUPS.to_vec())] {
            let timed = timed_passes(&one_submission(7, p, timing));
            assert_eq!(timed.iter().map(|t| t.0).collect::<Vec<_>>(), labels, "{timing:?}");
            assert!(timed.iter().enumerate().all(|(k, t)| t.1 == 2 * k as u32), "{timed:?}");
            assert!(timed.len() as u32 <= TIMED_PASSES);
        }
        assert!(timed_passes(&one_submission(7, p, PassTiming::Untimed)).is_empty());
    }
    let runs = some.map(|p| {
        [PassTiming::Untimed, PassTiming::Grouped, PassTiming::EachPass]
            .map(|timing| one_submission(7, p, timing))
            .into_iter()
            .chain([pass_run("plan", 7, p), pass_run("lattice", 7, p)])
    });
    for recording in [usual, active_cuts(7)].into_iter().chain(runs.into_iter().flatten()) {
        let mut in_pass = false;
        for command in &recording.commands {
            match *command {
                Command::Clear { buffer, .. } => {
                    assert!(bound(buffer), "clears {buffer:?}, which SUBDIVIDE does not bind");
                    in_pass = false;
                }
                Command::Pass { .. } => in_pass = true,
                Command::Dispatch { entry, .. } => assert!(entries.contains(&entry) && in_pass, "{entry}"),
                Command::DispatchIndirect { entry, args, .. } => {
                    assert!(entries.contains(&entry) && in_pass && bound(args), "{entry} from {args:?}")
                }
            }
        }
    }
}

/// Every buffer the subdivide stage binds is a typed handle the engines resolve (the recordings
/// name buffers only by handle).
#[test]
fn every_subdivide_binding_is_a_buffer_handle() {
    use twister::encoding::recording::SubdivideBuffer;
    for binding in twister::shader::SUBDIVIDE.bindings {
        assert!(SubdivideBuffer::bound_as(binding.name).is_some(), "{} has no SubdivideBuffer", binding.name);
    }
}
