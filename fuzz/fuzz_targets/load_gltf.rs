//! Any bytes as a .gltf file (and, for glTF, as a .glb): the loader returns a scene or an
//! error naming the file; a panic or an allocation beyond the fuzzer's limit is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use twister::core::scenes::load::load_scene;
use twister::Projection;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("twister-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    for ext in ["gltf", "glb"] {
        let path = dir.join(format!("input.{ext}"));
        if std::fs::write(&path, data).is_ok() {
            if let Err(e) = load_scene(path.to_str().unwrap(), &Projection::default()) {
                assert!(e.to_string().contains(path.to_str().unwrap()), "error does not name the file: {e}");
            }
        }
    }
});
