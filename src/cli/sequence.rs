//! `twister render --frames A..B`: a frame sequence of an animated scene (issue 18). The device,
//! pipelines, scene buffers and targets are made once; each frame poses the scene's rig at
//! frame / fps seconds (`core::animation`; the vertices by the GPU's skin stage, which reads only
//! the frame's matrices and weights), renders and writes its files atomically (all of a frame's
//! files or none: `output::write_all`).
//!
//! `--resume` skips frames whose files all exist; `--shard I/N` renders the frames whose index
//! ≡ I (mod N) (or the I-th of N contiguous blocks, `--shard-mode blocks`), so a scheduler's
//! array job fans a sequence out over machines sharing the output folder; `--stats FILE.jsonl`
//! appends one JSON line per frame. A frame's bytes depend on the frame alone (the pose is
//! computed from the rest pose, never accumulated), so shards and reruns give the same files.

use std::io::Write;
use std::path::PathBuf;

use glam::Vec3;

use crate::args::{RenderArgs, ShardMode, Viewer};
use crate::render::render_settings;
use crate::scene::{open_renderer, prepare};
use crate::writer::{frame_name, FrameRecord, FrameWriter};
use twister::core::projection::PanoramaKind;
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::output::{write_all, Layout};

/// The frames of `first..=last` shard `i` of `n` renders.
pub fn shard_frames(first: u32, last: u32, (i, n): (u32, u32), mode: ShardMode) -> Vec<u32> {
    let count = (last - first + 1) as u64;
    match mode {
        ShardMode::Interleave => (first..=last).filter(|f| (f - first) % n == i).collect(),
        ShardMode::Blocks => {
            let (start, end) = (count * i as u64 / n as u64, count * (i as u64 + 1) / n as u64);
            (start..end).map(|k| first + k as u32).collect()
        }
    }
}

/// Renders the sequence `args.frames` asks for.
pub fn render_sequence(args: &RenderArgs, (first, last): (u32, u32)) -> Result<()> {
    let settings = render_settings(args)?;
    for (given, option) in [(args.depth, "--depth"), (args.hdr, "--hdr"), (args.lod_overlay, "--lod-overlay")] {
        if given {
            return Err(Error::option(option, "writes one still: leave it out with --frames"));
        }
    }
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(Error::option("--fps", format!("must be between 0 and 1000 frames per second, got {}", args.fps)));
    }
    let panorama = settings.projection().panorama;
    let writer = FrameWriter::new(args, &settings, true)?;
    let stereo = match writer.layout() {
        Layout::TopBottom => twister::video::StereoMode::TopBottom,
        Layout::SideBySide => twister::video::StereoMode::LeftRight,
        _ => twister::video::StereoMode::Mono,
    };
    if let Some(video) = &args.video {
        if args.shard.is_some() {
            return Err(Error::option(
                "--video",
                "encodes the whole sequence: render the shards, then run once more with --resume --video",
            ));
        }
        if stereo == twister::video::StereoMode::Mono {
            return Err(Error::option("--video", "needs a one-image layout: --layout top-bottom or side-by-side"));
        }
        if args.format != twister::output::ImageFormat::Png {
            return Err(Error::option("--video", "encodes the PNG frames: leave --format png"));
        }
        twister::output::check_outputs(&[video.as_path()])?;
        ffmpeg_version()?;
    }
    let frames = match args.shard {
        Some(shard) => shard_frames(first, last, shard, args.shard_mode),
        None => (first..=last).collect(),
    };
    let gaze_path = args.gaze_path.as_deref().map(twister::core::visual_field::GazePath::read).transpose()?;
    let lod = args.view.lod()?;
    let viewer_path = match &args.viewer_path {
        Some(_) if matches!(args.view.viewer, Viewer::Camera(_)) => {
            return Err(Error::option("--viewer-path", "moves the viewer itself: leave out --viewer camera"))
        }
        Some(path) => {
            Some(twister::core::timeline::Timeline::read(path, "viewer_path", (3, 4), "time,x,y,z[,yaw]", |v| {
                let max = twister::core::scene::MAX_COORDINATE;
                (v[..3].iter().any(|c| c.abs() > max)).then(|| format!("coordinates within ±{max:e}"))
            })?)
        }
        None => None,
    };
    if gaze_path.is_some() && lod.is_none() {
        return Err(Error::option("--gaze-path", "steers the level of detail: use it with --lod visual-field"));
    }
    let (renderer, adapter) = open_renderer()?;
    let method = [settings.subdivision.method];
    let base_yaw = settings.view.yaw_deg;
    let mut prepared = prepare(&renderer, &args.scene, args.fit, &args.view, settings, false, &method)?;
    let base = prepared.settings;
    let clip = match (&prepared.scene.rig, &args.animation) {
        (Some(rig), Some(name)) => Some(rig.clip_index(name).ok_or_else(|| {
            let known: Vec<&str> = rig.clips.iter().map(|c| c.name.as_str()).collect();
            Error::option("--animation", format!("{name}: the file's animations are {}", known.join(", ")))
        })?),
        (Some(rig), None) => (!rig.clips.is_empty()).then_some(0),
        (None, Some(_)) => return Err(Error::option("--animation", format!("{} has no animations", args.scene))),
        (None, None) => None,
    };
    // With a gaze path, each frame selects its level of detail from the whole scene.
    let mut tracked = match (&gaze_path, &lod) {
        (Some(path), Some((params, _))) => Some((
            path,
            *params,
            twister::core::lod::LodChain::build(&prepared.scene, params.p3),
            twister::GpuScene::upload(&renderer.gpu, &prepared.scene)?,
        )),
        _ => None,
    };
    let camera = match args.view.viewer {
        Viewer::Camera(n) => Some(n),
        Viewer::At(_) => None,
    };
    let todo: Vec<u32> =
        frames.into_iter().filter(|&f| !(args.resume && writer.paths(Some(f)).iter().all(|p| p.exists()))).collect();
    if let Some(dir) = args.stats.as_deref().and_then(|p| p.parent()).filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, format!("cannot create the folder: {e}")))?;
    }
    let mut stats = match &args.stats {
        Some(path) => Some(
            std::fs::OpenOptions::new()
                .create(true)
                .append(args.resume)
                .write(true)
                .truncate(!args.resume)
                .open(path)
                .map_err(|e| Error::output(path, format!("cannot write: {e}")))?,
        ),
        None => None,
    };
    let progress = indicatif::ProgressBar::new(todo.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {per_sec}, ETA {eta}")
            .expect("a valid template"),
    );
    let start = std::time::Instant::now();
    // A writer thread encodes and writes frame k while the GPU draws frame k + 1 (one frame in
    // flight: bounded memory).
    type Done = (u32, f32, f64, twister::Frame, twister::RenderSettings, Option<twister::core::lod::LodSelection>);
    let (send, receive) = std::sync::mpsc::sync_channel::<Done>(1);
    std::thread::scope(|scope| -> Result<()> {
        let writing = scope.spawn(|| -> Result<()> {
            for (frame, time, ms_pose, rendered, drawn_with, selected) in receive {
                let t = std::time::Instant::now();
                let files = writer.files(&rendered, Some(frame))?;
                write_all(&files)?;
                let ms_write = t.elapsed().as_secs_f64() * 1e3;
                if let (Some(file), Some(path)) = (stats.as_mut(), &args.stats) {
                    let lod = crate::scene::lod_stats(&selected);
                    let record = FrameRecord {
                        frame: Some(frame),
                        time: Some(time),
                        ms_pose: Some(ms_pose),
                        ms_write,
                        files: Some(files.iter().map(|f| f.path.display().to_string()).collect()),
                        ..FrameRecord::new(&args.scene, &drawn_with, &rendered, &writer, &adapter, lod)
                    };
                    let line = serde_json::to_string(&record).expect("JSON of plain values");
                    writeln!(file, "{line}").map_err(|e| Error::output(path, format!("cannot write: {e}")))?;
                }
                progress.inc(1);
            }
            Ok(())
        });
        let drawn = (|| -> Result<()> {
            for &frame in &todo {
                let time = frame as f32 / args.fps;
                let t = std::time::Instant::now();
                if prepared.scene.rig.is_some() {
                    if base.subdivision.method == Method::Trace {
                        // The ray tracer's BVH is built on the CPU from the posed vertices.
                        prepared.scene.pose(clip, time);
                        prepared.gpu_scene.update_pose(&renderer.gpu, &prepared.scene)?;
                        prepared.gpu_scene.rebuild_bvh(&renderer.gpu, &prepared.scene)?;
                    } else {
                        // The skin stage poses the vertices on the GPU; only matrices and
                        // weights are uploaded.
                        let target = match tracked.as_mut() {
                            Some((_, _, _, whole)) => whole,
                            None => &mut prepared.gpu_scene,
                        };
                        renderer.pose(target, &mut prepared.scene, clip, time)?;
                    }
                }
                // The frame's settings: the base's, with the viewer the path or the posed camera puts.
                let mut settings = base;
                if let Some(path) = &viewer_path {
                    let v = path.at(time);
                    let yaw = base_yaw + v.get(3).copied().unwrap_or(0.0);
                    settings = base.with_viewer(Vec3::new(v[0], v[1], v[2]) * args.view.scale).with_yaw_deg(yaw);
                }
                if let Some(cam) = camera.and_then(|n| prepared.scene.cameras.get(n)) {
                    settings = base.with_viewer(Vec3::from(cam.position)).with_yaw_deg(base_yaw + cam.yaw_deg);
                }
                let mut selected = None;
                if let Some((path, params, chain, whole)) = &tracked {
                    let selection = chain.select(&prepared.scene, settings.view(), &path.at(time), params);
                    prepared.gpu_scene = whole.with_lod(&renderer.gpu, &selection);
                    selected = Some(selection);
                }
                let ms_pose = t.elapsed().as_secs_f64() * 1e3;
                let rendered = renderer.render(&prepared.gpu_scene, &settings)?;
                if send.send((frame, time, ms_pose, rendered, settings, selected)).is_err() {
                    break; // the writer stopped: its error is reported below
                }
            }
            Ok(())
        })();
        drop(send);
        let written = writing.join().expect("the writer thread does not panic");
        drawn.and(written)
    })?;
    progress.finish_and_clear();
    let skipped = (last - first + 1) as usize - todo.len();
    eprintln!(
        "{} frames rendered in {:.1} s{}",
        todo.len(),
        start.elapsed().as_secs_f64(),
        if skipped > 0 { format!(" ({skipped} skipped: complete, or another shard's)") } else { String::new() }
    );
    if let Some(video) = &args.video {
        let name = frame_name(0, &writer.image_names()[0]).replacen("000000", "%06d", 1);
        encode_video(video, &args.out.join(name), first, last - first + 1, args.fps, stereo, panorama)?;
        println!("{}", video.display());
    }
    Ok(())
}

/// The installed ffmpeg's first line, or one line saying how to install it.
fn ffmpeg_version() -> Result<String> {
    match std::process::Command::new("ffmpeg").arg("-version").output() {
        Ok(out) if out.status.success() => {
            Ok(String::from_utf8_lossy(&out.stdout).lines().next().unwrap_or("ffmpeg").to_string())
        }
        _ => Err(Error::option(
            "--video",
            "needs ffmpeg on PATH: install it (apt-get install ffmpeg, dnf install ffmpeg, brew install ffmpeg)",
        )),
    }
}

/// Encodes `count` frames from `first` (the numbered files `pattern`, `%06d` the frame) at `fps`
/// into `video` with ffmpeg (H.264, yuv420p, CRF 18, sizes padded to even), then adds the
/// spherical metadata and writes the file whole (temporary name, rename).
fn encode_video(
    video: &std::path::Path,
    pattern: &std::path::Path,
    first: u32,
    count: u32,
    fps: f32,
    stereo: twister::video::StereoMode,
    panorama: PanoramaKind,
) -> Result<()> {
    let missing = (first..first + count)
        .find(|f| !PathBuf::from(pattern.to_string_lossy().replace("%06d", &format!("{f:06}"))).exists());
    if let Some(f) = missing {
        return Err(Error::option(
            "--video",
            format!("frame {f} is missing: render it first (--resume renders only missing frames)"),
        ));
    }
    let temporary = std::env::temp_dir().join(format!("twister-video-{}.mp4", std::process::id()));
    let out = std::process::Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate", &fps.to_string(), "-start_number", &first.to_string(), "-i"])
        .arg(pattern)
        .args(["-frames:v", &count.to_string(), "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264"])
        .args(["-pix_fmt", "yuv420p", "-crf", "18", "-f", "mp4"])
        .arg(&temporary)
        .output()
        .map_err(|e| Error::option("--video", format!("cannot run ffmpeg: {e}")))?;
    let encoded = std::fs::read(&temporary);
    let _ = std::fs::remove_file(&temporary);
    if !out.status.success() {
        let why = String::from_utf8_lossy(&out.stderr);
        return Err(Error::output(video, format!("ffmpeg failed: {}", why.lines().last().unwrap_or("no message"))));
    }
    let encoded = encoded.map_err(|e| Error::output(video, format!("ffmpeg wrote nothing readable: {e}")))?;
    let name = video.display().to_string();
    let bytes = twister::video::with_spherical_metadata(&encoded, &name, stereo, panorama == PanoramaKind::Equirect)?;
    write_all(&[twister::output::OutputFile { path: video.to_path_buf(), bytes }])
}
