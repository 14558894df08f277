//! Animation and sequences (issue 18): glTF interpolation against hand-computed values
//! (InterpolationTest), a skinned pose drawn where the CPU evaluation puts it (RiggedSimple,
//! CesiumMan), and the sequence command's numbered, resumable, shardable, atomic outputs.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{Quat, Vec2, Vec3, Vec4};
use twister::core::scenes::animation::{pose_nodes, Interpolation, Property};
use twister::core::scenes::load::load_scene;
use twister::{Eye, GpuScene, Projection, RenderSettings, Scene, Vertical};

fn asset_scene(relative: &str) -> Scene {
    let path = common::asset(relative);
    load_scene(path.to_str().unwrap(), &Projection::default()).unwrap()
}

/// Every channel of InterpolationTest (STEP, LINEAR and CUBICSPLINE on translation, rotation and
/// scale) posed at its first key, halfway to the second, and at the second: the keys
/// themselves, and halfway the previous key (STEP), the average (LINEAR; for rotations the
/// normalised sum, which is where slerp's midpoint lies), or the Hermite curve at s = ½:
/// ½·v₀ + ⅛·Δt·b₀ + ½·v₁ − ⅛·Δt·a₁ (CUBICSPLINE).
#[test]
fn interpolation_test_poses_at_hand_computed_values() {
    if !common::assets_present() {
        return;
    }
    let scene = asset_scene("gltf/InterpolationTest/glTF-Binary/InterpolationTest.glb");
    let rig = scene.rig.as_ref().expect("an animated file has a rig");
    let mut seen = Vec::new();
    for clip in &rig.clips {
        for channel in &clip.channels {
            let s = &channel.sampler;
            let w = s.width;
            let cubic = s.interpolation == Interpolation::CubicSpline;
            let key = |k: usize, part: usize| -> Vec<f32> {
                let start = if cubic { (3 * k + part) * w } else { k * w };
                s.values[start..start + w].to_vec()
            };
            let (t0, t1) = (s.times[0], s.times[1]);
            let dt = t1 - t0;
            let (v0, v1) = (key(0, 1), key(1, 1));
            let half: Vec<f32> = match (s.interpolation, channel.property) {
                (Interpolation::Step, _) => v0.clone(),
                (Interpolation::Linear, Property::Rotation) => {
                    let (a, b) = (Vec4::from_slice(&v0), Vec4::from_slice(&v1));
                    let b = if a.dot(b) < 0.0 { -b } else { b };
                    (a + b).normalize().to_array().to_vec()
                }
                (Interpolation::Linear, _) => v0.iter().zip(&v1).map(|(a, b)| 0.5 * (a + b)).collect(),
                (Interpolation::CubicSpline, property) => {
                    let (b0, a1) = (key(0, 2), key(1, 0));
                    let p: Vec<f32> =
                        (0..w).map(|i| 0.5 * v0[i] + 0.125 * dt * b0[i] + 0.5 * v1[i] - 0.125 * dt * a1[i]).collect();
                    if property == Property::Rotation {
                        Vec4::from_slice(&p).normalize().to_array().to_vec()
                    } else {
                        p
                    }
                }
            };
            for (t, want) in [(t0, v0.clone()), (0.5 * (t0 + t1), half), (t1, v1.clone())] {
                let pose = &pose_nodes(&rig.nodes, Some(clip), t)[channel.node];
                let got: Vec<f32> = match channel.property {
                    Property::Translation => pose.translation.to_array().to_vec(),
                    Property::Scale => pose.scale.to_array().to_vec(),
                    Property::Rotation => {
                        // q and −q are the same rotation.
                        let (q, w) = (pose.rotation, Quat::from_slice(&want));
                        (if q.dot(w) < 0.0 { -q } else { q }).to_array().to_vec()
                    }
                    Property::Weights => pose.weights.clone(),
                };
                let close = got.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-4);
                assert!(
                    close,
                    "{} {:?} {:?} at {t}: {got:?}, want {want:?}",
                    clip.name, s.interpolation, channel.property
                );
            }
            seen.push((s.interpolation, channel.property));
        }
    }
    for i in [Interpolation::Step, Interpolation::Linear, Interpolation::CubicSpline] {
        for p in [Property::Translation, Property::Rotation, Property::Scale] {
            assert!(seen.contains(&(i, p)), "InterpolationTest has {i:?} on {p:?}");
        }
    }
}

/// The pixels an object covers in the left eye, as a box (min, max), or None.
fn object_box(frame: &twister::Frame, object: u32) -> Option<(Vec2, Vec2)> {
    let m = frame.measurement.as_ref().expect("measured");
    let width = frame.left.width;
    let mut b: Option<(Vec2, Vec2)> = None;
    for (i, &o) in m.object[0].iter().enumerate() {
        if o == object + 1 {
            let p = Vec2::new((i as u32 % width) as f32 + 0.5, (i as u32 / width) as f32 + 0.5);
            b = Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))));
        }
    }
    b
}

/// A skinned pose is drawn where the CPU evaluation puts it: RiggedSimple at t = 1 s and
/// CesiumMan at 0.5 s, posed (joints × inverse bind matrices, weighted), uploaded as the only
/// change, rendered; the drawn pixels' box is the box of the posed vertices projected (within 2
/// px), and differs from the rest pose's; posed by the GPU's skin stage instead, the same pixels
/// are drawn, and the stage's twin gives the CPU pose's vertices.
#[test]
fn a_skinned_pose_is_drawn_where_the_cpu_evaluation_puts_it() {
    if !common::assets_present() {
        return;
    }
    let r = common::renderer();
    for (file, t) in
        [("gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb", 1.0), ("gltf/CesiumMan/glTF-Binary/CesiumMan.glb", 0.5)]
    {
        let p = Projection { width: 720, height: 240, vertical: Vertical::Exact, ..Projection::default() };
        let mut scene = asset_scene(file);
        scene.fit(2.5, &p).unwrap();
        let settings = RenderSettings::new(p).with_measure_error(true);
        let mut gpu_scene = GpuScene::upload(&r.gpu, &scene).unwrap();
        let rest = object_box(&r.render(&gpu_scene, &settings).unwrap(), 0).expect("drawn at rest");
        let rig = scene.rig.as_ref().expect("a skinned file has a rig");
        assert!(!rig.skins.is_empty() && !rig.clips.is_empty(), "{file}");
        scene.pose(Some(0), t);
        gpu_scene.update_pose(&r.gpu, &scene).unwrap();
        let frame = r.render(&gpu_scene, &settings).unwrap();
        let drawn = object_box(&frame, 0).expect("drawn posed");
        // Where the posed vertices project (the CPU twin of the projection).
        let points: Vec<Vec3> = scene.vertices.iter().map(|v| Vec3::from(v.position)).collect();
        let pixels = twister::cpu::project_points::project_points(&p, Eye::Left, &points);
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for q in pixels.iter().filter(|q| q[3] == 1.0) {
            lo = lo.min(Vec2::new(q[0], q[1]));
            hi = hi.max(Vec2::new(q[0], q[1]));
        }
        let off = (drawn.0 - lo).abs().max_element().max((drawn.1 - hi).abs().max_element());
        assert!(off <= 2.0, "{file}: drawn {drawn:?}, the posed vertices project to {lo}..{hi}");
        let moved = (drawn.0 - rest.0).abs().max_element().max((drawn.1 - rest.1).abs().max_element());
        assert!(moved >= 3.0, "{file}: the pose moved the drawing by {moved} px only");
        // The GPU's skin stage poses the same: the same pixels drawn, and its twin gives the
        // vertices the CPU pose gave.
        let posed_on_cpu = scene.vertices.clone();
        let mut rest_scene = asset_scene(file);
        rest_scene.fit(2.5, &p).unwrap();
        let mut on_gpu = GpuScene::upload(&r.gpu, &rest_scene).unwrap();
        r.pose(&mut on_gpu, &mut rest_scene, Some(0), t).unwrap();
        let gpu_box = object_box(&r.render(&on_gpu, &settings).unwrap(), 0).expect("drawn posed on the GPU");
        let off = (gpu_box.0 - drawn.0).abs().max_element().max((gpu_box.1 - drawn.1).abs().max_element());
        assert!(off <= 1.0, "{file}: posed on the GPU {gpu_box:?}, on the CPU {drawn:?}");
        let rig = rest_scene.rig.as_deref().unwrap();
        let mut twin = rest_scene.vertices.clone();
        twister::cpu::skin::skin(
            &twister::cpu::skin::SkinData::of(rig),
            &twister::cpu::skin::SkinFrame::of(rig, Some(0), t),
            &mut twin,
        );
        for (a, b) in twin.iter().zip(&posed_on_cpu) {
            let d = (Vec3::from(a.position) - Vec3::from(b.position)).length();
            assert!(d < 1e-4, "{file}: the skin twin and Scene::pose differ by {d} m");
        }
    }
}

fn sequence(out: &Path, extra: &[&str]) -> std::process::Output {
    let scene = common::asset("gltf/AnimatedCube/glTF/AnimatedCube.gltf");
    let output = common::twister()
        .args(["render", scene.to_str().unwrap(), "--fit", "2.5", "--width", "128", "--height", "48", "--fps", "8"])
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    output
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p: PathBuf| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect();
    v.sort();
    v
}

/// `--frames 0..9`: numbered files per eye, one stats line per frame, frames that differ as the
/// cube turns; `--resume` renders only missing frames; three interleaved shards and two blocks
/// give the same bytes as one run; a run killed mid-way leaves only whole frames.
#[test]
fn sequences_are_numbered_resumable_shardable_and_atomic() {
    if !common::assets_present() {
        return;
    }
    let root = common::TempDir::new(format!("twister-seq-{}", std::process::id()));
    let all = root.join("all");
    let stats = root.join("stats.jsonl");
    sequence(&all, &["--frames", "0..9", "--stats", stats.to_str().unwrap()]);
    let full = files(&all);
    let names: Vec<&str> = full.iter().map(|(n, _)| n.as_str()).collect();
    let want: Vec<String> =
        (0..10).flat_map(|k| [format!("frame_{k:06}_left.png"), format!("frame_{k:06}_right.png")]).collect();
    assert_eq!(names, want);
    let lines: Vec<serde_json::Value> =
        std::fs::read_to_string(&stats).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.iter().map(|l| l["frame"].as_u64().unwrap()).collect::<Vec<_>>(), (0..10).collect::<Vec<_>>());
    assert!((lines[4]["time"].as_f64().unwrap() - 0.5).abs() < 1e-6, "frame 4 at 4/8 s");
    assert_ne!(full[0].1, full[2].1, "the cube turns between frames 0 and 1");
    // Resume: nothing to do, then only the frame whose file went missing.
    let resumed = sequence(&all, &["--frames", "0..9", "--resume"]);
    assert!(String::from_utf8_lossy(&resumed.stderr).contains("0 frames rendered"));
    std::fs::remove_file(all.join("frame_000007_right.png")).unwrap();
    let resumed = sequence(&all, &["--frames", "0..9", "--resume"]);
    assert!(String::from_utf8_lossy(&resumed.stderr).contains("1 frames rendered"));
    assert_eq!(files(&all), full, "the resumed frame has the same bytes");
    // Shards, interleaved and in blocks: the same bytes as one run.
    for (mode, n) in [("interleave", 3), ("blocks", 2)] {
        let dir = root.join(mode);
        for i in 0..n {
            sequence(&dir, &["--frames", "0..9", "--shard", &format!("{i}/{n}"), "--shard-mode", mode]);
        }
        assert_eq!(files(&dir), full, "{n} {mode} shards");
    }
    // Killed mid-way: every file there is a whole PNG (written under a temporary name, then
    // renamed), and a resumed run completes the sequence with the same bytes.
    let killed = root.join("killed");
    let scene = common::asset("gltf/AnimatedCube/glTF/AnimatedCube.gltf");
    let mut child = common::twister()
        .args(["render", scene.to_str().unwrap(), "--fit", "2.5", "--width", "128", "--height", "48", "--fps", "8"])
        .args(["--frames", "0..9", "--out", killed.to_str().unwrap()])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !killed.join("frame_000002_left.png").exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    for (name, bytes) in files(&killed) {
        if name.ends_with(".png") && !name.starts_with('.') {
            image::load_from_memory(&bytes).unwrap_or_else(|e| panic!("{name} is not a whole PNG: {e}"));
        }
    }
    sequence(&killed, &["--frames", "0..9", "--resume"]);
    assert_eq!(files(&killed), full, "resumed after the kill");
    std::fs::remove_dir_all(&root).unwrap();
}

/// The Slurm job-array example renders, task by task, the same frames as one run.
#[test]
fn the_slurm_example_shards_a_sequence() {
    if !common::assets_present() {
        return;
    }
    let root = common::TempDir::new(format!("twister-slurm-{}", std::process::id()));
    let scene = common::asset("gltf/AnimatedCube/glTF/AnimatedCube.gltf");
    let bin = Path::new(env!("CARGO_BIN_EXE_twister")).parent().unwrap().to_path_buf();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let small = ["--fit", "2.5", "--width", "128", "--height", "48", "--fps", "8"];
    for task in 0..3 {
        let out = Command::new("bash")
            .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/farm/slurm_array.sh"))
            .args([scene.to_str().unwrap(), "0", "5", root.join("array").to_str().unwrap()])
            .args(small)
            .env("PATH", &path)
            .env("NODEVICE_SELECT", "1")
            .env("SLURM_ARRAY_TASK_ID", task.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", "3")
            .output()
            .unwrap();
        assert!(out.status.success(), "task {task}: {}", String::from_utf8_lossy(&out.stderr));
    }
    sequence(&root.join("one"), &["--frames", "0..5"]);
    let pngs = |dir: &Path| files(dir).into_iter().filter(|(n, _)| n.ends_with(".png")).collect::<Vec<_>>();
    assert_eq!(pngs(&root.join("array")), pngs(&root.join("one")));
    assert_eq!(files(&root.join("array")).iter().filter(|(n, _)| n.ends_with(".jsonl")).count(), 3);
    std::fs::remove_dir_all(&root).unwrap();
}

/// The video track's first sample entry, as a box path.
const VIDEO_ENTRY: [&str; 7] = ["moov", "trak", "mdia", "minf", "stbl", "stsd", "avc1"];

/// ffprobe's first stream of `file`, its frames counted.
fn probe(file: &Path) -> serde_json::Value {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-show_streams", "-of", "json"])
        .arg(file)
        .output()
        .expect("ffprobe (scripts/test.sh installs ffmpeg)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()["streams"][0].clone()
}

/// `from` copied to `to` by ffmpeg (no re-encoding), with `extra` options.
fn ffmpeg_copy(from: &Path, to: &Path, extra: &[&str]) {
    let status = Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-i"])
        .arg(from)
        .args(["-c", "copy"])
        .args(extra)
        .arg(to)
        .status()
        .unwrap();
    assert!(status.success());
}

/// `--video`: the sequence encoded by ffmpeg, with Google's spherical metadata in the video's
/// sample entry — read back by our own box walk (st3d top-bottom; sv3d → proj → equi) and by
/// ffprobe (Stereo 3D "top and bottom", Spherical Mapping "equirectangular"), every frame there;
/// then re-tagged as VR180 and as a cubemap (`video_retagged_*`). Without ffmpeg on PATH: one
/// line naming the install command. (scripts/test.sh installs ffmpeg where it is missing.)
#[test]
fn a_video_carries_the_spherical_metadata() {
    if !common::assets_present() {
        return;
    }
    use twister::video::{find_boxes, find_spherical_v1, StereoMode};
    let root = common::TempDir::new(format!("twister-video-{}", std::process::id()));
    let video = root.join("cube.mp4");
    let scene = common::asset("gltf/AnimatedCube/glTF/AnimatedCube.gltf");
    let made = common::twister()
        .args(["render", scene.to_str().unwrap(), "--fit", "2.5", "--panorama", "equirect", "--width", "128"])
        .args(["--frames", "0..11", "--fps", "12", "--out", root.join("frames").to_str().unwrap(), "--video"])
        .arg(&video)
        .output()
        .unwrap();
    assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
    let mp4 = std::fs::read(&video).unwrap();
    let st3d = find_boxes(&mp4, &[&VIDEO_ENTRY[..], &["st3d"]].concat());
    assert_eq!(st3d.len(), 1);
    assert_eq!(st3d[0][4], StereoMode::TopBottom as u8, "st3d: version/flags, then the stereo mode");
    assert_eq!(find_boxes(&mp4, &[&VIDEO_ENTRY[..], &["sv3d", "proj", "equi"]].concat()).len(), 1);
    let stream = probe(&video);
    assert_eq!(stream["nb_read_frames"], "12");
    assert_eq!((stream["width"].as_u64(), stream["height"].as_u64()), (Some(128), Some(128)), "top-bottom");
    let side: Vec<String> =
        stream["side_data_list"].as_array().unwrap().iter().map(|d| d.to_string()).collect::<Vec<_>>();
    assert!(side.iter().any(|d| d.contains("top and bottom")), "{side:?}");
    assert!(side.iter().any(|d| d.contains("equirectangular")), "{side:?}");
    let v1 = find_spherical_v1(&mp4);
    assert_eq!(v1.len(), 1, "the sphere's video carries one V1 box");
    assert!(
        v1[0].contains("<GSpherical:StereoMode>top-bottom<") && v1[0].contains("<GSpherical:FullPanoWidthPixels>128<")
    );
    video_retagged_as_vr180(&root, &video);
    video_retagged_as_a_cubemap(&root, &video);
    // No ffmpeg: one line.
    let out = common::twister()
        .args(["render", scene.to_str().unwrap(), "--frames", "0..1", "--layout", "top-bottom", "--video"])
        .arg(root.join("none.mp4"))
        .arg("--out")
        .arg(root.join("none"))
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("ffmpeg") && err.contains("install"), "{err}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// The video with its moov first (faststart, so the chunk offsets must move) re-tagged as VR180
/// side by side: equi's bounds crop a quarter off each side, the V1 XML gives the same crop in
/// pixels, and every frame still decodes.
fn video_retagged_as_vr180(root: &Path, video: &Path) {
    use twister::core::panoramas::projection::PanoramaKind;
    use twister::video::{find_boxes, find_spherical_v1, with_spherical_metadata, StereoMode};
    let fast = root.join("fast.mp4");
    ffmpeg_copy(video, &fast, &["-movflags", "+faststart"]);
    let tagged = with_spherical_metadata(
        &std::fs::read(&fast).unwrap(),
        "fast",
        StereoMode::LeftRight,
        PanoramaKind::Vr180,
        [64, 64],
    )
    .unwrap();
    std::fs::write(&fast, &tagged).unwrap();
    let equi = find_boxes(&tagged, &[&VIDEO_ENTRY[..], &["sv3d", "proj", "equi"]].concat());
    let bounds: Vec<u32> = equi[0][4..20].chunks(4).map(|b| u32::from_be_bytes(b.try_into().unwrap())).collect();
    assert_eq!(bounds, [0, 0, 1 << 30, 1 << 30], "top, bottom, left, right");
    let v1 = find_spherical_v1(&tagged);
    assert_eq!(v1.len(), 1);
    for tag in [
        "StereoMode>left-right<",
        "CroppedAreaImageWidthPixels>64<",
        "FullPanoWidthPixels>128<",
        "CroppedAreaLeftPixels>32<",
    ] {
        assert!(v1[0].contains(tag), "{tag}: {}", v1[0]);
    }
    let stream = probe(&fast);
    assert_eq!(stream["nb_read_frames"], "12", "every frame still decodes");
    let side = stream["side_data_list"].to_string();
    assert!(side.contains("side by side") && side.contains("tiled equirectangular"), "{side}");
    // ffprobe gives the bounds in pixels of a full panorama twice the frame's width (rounded its
    // own way): a quarter of that, the frame's half, off each side.
    let mapping = stream["side_data_list"].as_array().unwrap().iter().find(|d| d["bound_left"].is_u64()).unwrap();
    let (l, r) = (mapping["bound_left"].as_u64().unwrap(), mapping["bound_right"].as_u64().unwrap());
    assert!(l + r == 128 && l.abs_diff(64) <= 2, "{side}");
}

/// The video re-tagged as a stereo cubemap (top-bottom): `cbmp` layout 0 (the 3×2 grid), no
/// padding, and no V1 box (V1 describes equirectangular images only); ffprobe reads a cubemap.
fn video_retagged_as_a_cubemap(root: &Path, video: &Path) {
    use twister::core::panoramas::projection::PanoramaKind;
    use twister::video::{find_boxes, find_spherical_v1, with_spherical_metadata, StereoMode};
    let cube = root.join("cube-map.mp4");
    ffmpeg_copy(video, &cube, &[]);
    let untagged = std::fs::read(&cube).unwrap();
    assert!(
        find_boxes(&untagged, &[&VIDEO_ENTRY[..], &["sv3d"]].concat()).is_empty(),
        "ffmpeg writes no sv3d of its own"
    );
    let tagged =
        with_spherical_metadata(&untagged, "cube", StereoMode::TopBottom, PanoramaKind::Cubemap, [96, 64]).unwrap();
    std::fs::write(&cube, &tagged).unwrap();
    let cbmp = find_boxes(&tagged, &[&VIDEO_ENTRY[..], &["sv3d", "proj", "cbmp"]].concat());
    assert_eq!(cbmp.len(), 1);
    assert_eq!(&cbmp[0][4..12], &[0; 8], "layout 0, padding 0");
    assert!(find_boxes(&tagged, &[&VIDEO_ENTRY[..], &["sv3d", "proj", "equi"]].concat()).is_empty());
    assert!(find_spherical_v1(&tagged).is_empty());
    let stream = probe(&cube);
    assert_eq!(stream["nb_read_frames"], "12", "every frame still decodes");
    let side = stream["side_data_list"].to_string();
    assert!(side.contains("top and bottom") && side.contains("cubemap"), "{side}");
}

/// Options of a sequence without `--frames`, an unknown animation, and a still-only option with
/// `--frames` are one line each.
#[test]
fn sequence_options_are_checked() {
    if !common::assets_present() {
        return;
    }
    let scene = common::asset("gltf/AnimatedCube/glTF/AnimatedCube.gltf");
    for (args, want) in [
        (vec!["--resume"], "--resume"),
        (vec!["--shard", "1/3"], "--shard"),
        (vec!["--frames", "0..2", "--animation", "nope"], "--animation"),
        (vec!["--frames", "0..2", "--depth"], "--depth"),
        (vec!["--frames", "3..1"], "--frames"),
        (vec!["--frames", "0..2", "--shard", "3/3"], "--shard"),
        (vec!["--frames", "0..2", "--fps", "0"], "--fps"),
        (vec!["--video", "x.mp4"], "--video"),
        (vec!["--frames", "0..2", "--video", "x.mp4"], "--video"),
        (vec!["--frames", "0..2", "--layout", "top-bottom", "--shard", "0/2", "--video", "x.mp4"], "--video"),
    ] {
        let out = common::twister()
            .args(["render", scene.to_str().unwrap(), "--width", "64", "--height", "32", "--out", "/nonexistent/x"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(want) && err.trim().lines().count() <= 2, "{args:?}: {err}");
    }
}

/// A glTF file whose camera node moves from x = 0 to x = 1 m in one second (LINEAR), looking at a
/// quad 3 m ahead.
fn moving_camera_file(dir: &Path) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let quad = [[-1.0f32, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
    bin.extend(quad.iter().flatten().flat_map(|f| f.to_le_bytes()));
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0.0f32, 1.0].iter().flat_map(|f| f.to_le_bytes()));
    bin.extend([0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0].iter().flat_map(|f| f.to_le_bytes()));
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "buffers": [{ "byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", common::base64(&bin)) }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 48 },
            { "buffer": 0, "byteOffset": 48, "byteLength": 12 },
            { "buffer": 0, "byteOffset": 60, "byteLength": 8 },
            { "buffer": 0, "byteOffset": 68, "byteLength": 24 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0] },
            { "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" },
            { "bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1] },
            { "bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3" }
        ],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "cameras": [{ "type": "perspective", "perspective": { "yfov": 1.0, "znear": 0.1 } }],
        "nodes": [
            { "mesh": 0, "translation": [0, 0, -3] },
            { "camera": 0, "name": "dolly" }
        ],
        "scenes": [{ "nodes": [0, 1] }],
        "animations": [{
            "channels": [{ "sampler": 0, "target": { "node": 1, "path": "translation" } }],
            "samplers": [{ "input": 2, "output": 3, "interpolation": "LINEAR" }]
        }]
    });
    let path = dir.join("dolly.gltf");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(&path, json.to_string()).unwrap();
    path
}

/// An animated camera moves the viewer as the file says: frames 0–2 at 2 fps with `--viewer
/// camera` are, byte for byte, stills rendered with the viewer at x = 0, 0.5 and 1 m.
#[test]
fn an_animated_camera_moves_the_viewer() {
    let root = common::TempDir::new(format!("twister-dolly-{}", std::process::id()));
    let file = moving_camera_file(&root);
    let small = ["--width", "128", "--height", "48"];
    let run = |extra: &[&str]| {
        let out = common::twister().arg("render").arg(&file).args(small).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    run(&["--viewer", "camera", "--frames", "0..2", "--fps", "2", "--out", root.join("seq").to_str().unwrap()]);
    for (k, x) in ["0", "0.5", "1"].into_iter().enumerate() {
        let still = root.join(format!("still{k}"));
        run(&["--viewer", &format!("{x},0,0"), "--out", still.to_str().unwrap()]);
        for eye in ["left", "right"] {
            let a = std::fs::read(root.join("seq").join(format!("frame_{k:06}_{eye}.png"))).unwrap();
            let b = std::fs::read(still.join(format!("{eye}.png"))).unwrap();
            let (a, b) = (image::load_from_memory(&a).unwrap(), image::load_from_memory(&b).unwrap());
            assert!(a == b, "frame {k} ({eye}) is not the still at x = {x}");
        }
    }
    std::fs::remove_dir_all(&root).unwrap();
}

/// `--gaze-path`: the tracked viewer's gaze steers each frame's level of detail — frames 0–2 at
/// 2 fps of a path turning from yaw 0 to 180° in one second are, pixel for pixel, stills with
/// `--gaze 0,0`, `90,0` and `180,0`; each frame's stats line has its selection. A malformed row
/// is one line naming the file and the row.
#[test]
fn a_gaze_path_steers_each_frames_level_of_detail() {
    let root = common::TempDir::new(format!("twister-gaze-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let path = root.join("gaze.csv");
    std::fs::write(&path, "time,yaw,pitch\n0,0,0\n1,180,0\n").unwrap();
    let lod = ["--lod", "visual-field", "--width", "256", "--height", "64"];
    let run = |extra: &[&str]| {
        let out = common::twister().args(["render", "builtin:demo"]).args(lod).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    let stats = root.join("stats.jsonl");
    run(&["--gaze-path", path.to_str().unwrap(), "--frames", "0..2", "--fps", "2", "--out"]
        .into_iter()
        .chain([root.join("seq").to_str().unwrap(), "--stats", stats.to_str().unwrap()])
        .collect::<Vec<_>>());
    let lines: Vec<serde_json::Value> =
        std::fs::read_to_string(&stats).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(lines.iter().all(|l| l["lod"]["triangles_selected"].as_u64().is_some()), "{lines:?}");
    assert_ne!(lines[0]["lod"], lines[2]["lod"], "turning the gaze changes the selection");
    for (k, yaw) in ["0", "90", "180"].into_iter().enumerate() {
        let still = root.join(format!("still{k}"));
        run(&["--gaze", &format!("{yaw},0"), "--out", still.to_str().unwrap()]);
        for eye in ["left", "right"] {
            let a = image::open(root.join("seq").join(format!("frame_{k:06}_{eye}.png"))).unwrap();
            let b = image::open(still.join(format!("{eye}.png"))).unwrap();
            assert!(a == b, "frame {k} ({eye}) is not the still gazing at yaw {yaw}");
        }
    }
    std::fs::write(&path, "0,0,0\n1,nope,0\n").unwrap();
    let out = common::twister()
        .args(["render", "builtin:demo"])
        .args(lod)
        .args(["--frames", "0..1", "--gaze-path", path.to_str().unwrap(), "--out", root.join("x").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("gaze.csv") && err.contains("row 2"), "{err}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// `--viewer-path`: the viewer moves through a still scene as the CSV says — frame 1 of 0–2 at
/// 2 fps, halfway between rows (0, 0, 0, yaw 0) and (0.4, 0.1, −0.3, yaw 45) at 0 and 1 s, is
/// pixel for pixel the still with `--viewer 0.2,0.05,-0.15 --yaw 22.5`, and frame 2 the last row.
#[test]
fn a_viewer_path_moves_the_viewer_through_a_still_scene() {
    let root = common::TempDir::new(format!("twister-walk-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let path = root.join("walk.csv");
    std::fs::write(&path, "# time, x, y, z, yaw\n0,0,0,0,0\n1,0.4,0.1,-0.3,45\n").unwrap();
    let small = ["--width", "256", "--height", "64"];
    let run = |extra: &[&str]| {
        let out = common::twister().args(["render", "builtin:demo"]).args(small).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    let seq = root.join("seq");
    run(&["--viewer-path", path.to_str().unwrap(), "--frames", "0..2", "--fps", "2", "--out", seq.to_str().unwrap()]);
    for (k, viewer, yaw) in [(1, "0.2,0.05,-0.15", "22.5"), (2, "0.4,0.1,-0.3", "45")] {
        let still = root.join(format!("still{k}"));
        run(&["--viewer", viewer, "--yaw", yaw, "--out", still.to_str().unwrap()]);
        for eye in ["left", "right"] {
            let a = image::open(seq.join(format!("frame_{k:06}_{eye}.png"))).unwrap();
            let b = image::open(still.join(format!("{eye}.png"))).unwrap();
            assert!(a == b, "frame {k} ({eye}) is not the still at {viewer}, yaw {yaw}");
        }
    }
    std::fs::remove_dir_all(&root).unwrap();
}

/// `--head-path`: a tracked head moves before the cylinder as the CSV says — frame 1 of 0–1 at
/// 1 fps is pixel for pixel the still with `--head` at the last row, frame 0 the first; the
/// path's misuses are one line each.
#[test]
fn a_head_path_moves_the_tracked_head() {
    let root = common::TempDir::new(format!("twister-head-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let path = root.join("head.csv");
    std::fs::write(&path, "# time, x, y, z, yaw\n0,0,0,0,0\n1,0.3,0.1,-0.2,20\n").unwrap();
    let small = ["--width", "256", "--height", "64", "--method", "vertex"];
    let run =
        |extra: &[&str]| common::twister().args(["render", "builtin:demo"]).args(small).args(extra).output().unwrap();
    let seq = root.join("seq");
    let out =
        run(&["--head-path", path.to_str().unwrap(), "--frames", "0..1", "--fps", "1", "--out", seq.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for (k, head) in [(0, "0,0,0"), (1, "0.3,0.1,-0.2,20")] {
        let still = root.join(format!("still{k}"));
        let out = run(&["--head", head, "--out", still.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        for eye in ["left", "right"] {
            let a = image::open(seq.join(format!("frame_{k:06}_{eye}.png"))).unwrap();
            let b = image::open(still.join(format!("{eye}.png"))).unwrap();
            assert!(a == b, "frame {k} ({eye}) is not the still with --head {head}");
        }
    }
    let p = path.to_str().unwrap();
    for (extra, needle) in [
        (&["--head-path", p][..], "--head-path: belongs to a sequence"),
        (&["--head-path", p, "--frames", "0..1", "--head", "0,0,0"], "--head-path: moves the head itself"),
        (
            &["--head-path", p, "--frames", "0..1", "--panorama", "equirect"],
            "--head-path: a tracked head looks at the cylinder",
        ),
        (&["--head-path", p, "--frames", "0..1", "--vertical", "paper"], "--head-path: a tracked head draws"),
    ] {
        let out = run(&[extra, &["--out", root.join("bad").to_str().unwrap()]].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(needle) && err.lines().count() == 1, "{extra:?}: {err}");
    }
    // A row that puts the eyes on the screen: one line naming the option.
    std::fs::write(&path, "0,0,0,0\n1,0.99,0,0\n").unwrap();
    let out = run(&["--head-path", p, "--frames", "0..1", "--fps", "1", "--out", root.join("far").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("the eyes reach the screen"), "{err}");
    std::fs::remove_dir_all(&root).unwrap();
}
