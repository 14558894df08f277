//! `twister render --frames A..B`: a frame sequence of an animated scene (issue 18). The device,
//! pipelines, scene buffers and targets are made once; each frame poses the scene's rig at
//! frame / fps seconds (`core::scenes::animation`; the vertices by the GPU's skin stage, which reads only
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
use crate::scene::{open_renderer, prepare_loaded, Prepared};
use crate::writer::{frame_name, FrameRecord, FrameWriter};
use twister::core::detail::lod::{LodChain, LodParams, LodSelection};
use twister::core::detail::visual_field::GazePath;
use twister::core::panoramas::projection::PanoramaKind;
use twister::core::scenes::timeline::Timeline;
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::output::{write_all, Layout};
use twister::video::StereoMode;

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

/// A drawn frame on its way to the writer thread: its number, time, the pose's milliseconds,
/// the frame, the settings it was drawn with and its level-of-detail selection.
struct Drawn {
    frame: u32,
    /// The view drawn: a CAVE's wall (its writer), or 0.
    view: usize,
    time: f32,
    ms_pose: f64,
    rendered: twister::Frame,
    settings: twister::RenderSettings,
    selected: Option<LodSelection>,
    /// A frame drawn in tiles: its images, already written (streamed); None: `rendered` holds them.
    written: Option<Vec<PathBuf>>,
}

/// With a gaze path, each frame selects its level of detail from the whole scene: the path,
/// the parameters, the scene's chains and the whole scene uploaded.
struct Tracked {
    path: GazePath,
    params: LodParams,
    chain: LodChain,
    whole: twister::GpuScene,
}

/// What draws a sequence's frames: the renderer, the placed scene, the base settings and what
/// moves from frame to frame (the clip, the viewer path, the file camera, the gaze path).
struct Sequence<'a> {
    args: &'a RenderArgs,
    renderer: &'a twister::Renderer,
    prepared: Prepared,
    base: twister::RenderSettings,
    /// `--yaw` before a file camera's yaw was added (a posed camera adds its own per frame).
    base_yaw: f32,
    clip: Option<usize>,
    viewer_path: Option<Timeline>,
    /// `--head-path`: the tracked head over time.
    head_path: Option<Timeline>,
    camera: Option<usize>,
    tracked: Option<Tracked>,
    /// A CAVE's walls (their projections; `ViewArgs::cave_walls`), or none: one view.
    walls: Vec<twister::Projection>,
    /// Each view's writer (a frame drawn in tiles is written as it is drawn).
    writers: Vec<FrameWriter>,
}

impl Sequence<'_> {
    /// Poses the scene at frame `frame`, places the viewer, selects the level of detail, draws
    /// each view (a CAVE's walls, or the one panorama).
    fn draw(&mut self, frame: u32) -> Result<Vec<Drawn>> {
        let time = frame as f32 / self.args.fps;
        let t = std::time::Instant::now();
        self.pose(time)?;
        let settings = self.frame_settings(time);
        let mut selected = None;
        if let Some(Tracked { path, params, chain, whole }) = &self.tracked {
            let selection = chain.select(&self.prepared.scene, settings.view(), &path.at(time), params);
            self.prepared.gpu_scene = whole.with_lod(&self.renderer.gpu, &selection);
            selected = Some(selection);
        }
        let ms_pose = t.elapsed().as_secs_f64() * 1e3;
        let views = self.views(settings);
        let mut drawn = Vec::with_capacity(views.len());
        for (view, settings) in views.into_iter().enumerate() {
            let selected = selected.clone();
            // Larger than the adapter draws at once: in tiles, written now (streamed).
            if self.renderer.tiles(&settings, self.args.max_tile).is_some() {
                let one = [(settings, self.writers[view].clone())];
                let (paths, stats) = crate::tiled::stream_views(
                    self.args,
                    self.renderer,
                    &self.prepared.gpu_scene,
                    &one,
                    Some(frame),
                    |_| None,
                )?;
                let rendered = crate::tiled::stats_frame(&stats[0].0);
                drawn.push(Drawn { frame, view, time, ms_pose, rendered, settings, selected, written: Some(paths) });
                continue;
            }
            let rendered = self.renderer.render(&self.prepared.gpu_scene, &settings)?;
            drawn.push(Drawn { frame, view, time, ms_pose, rendered, settings, selected, written: None });
        }
        Ok(drawn)
    }

    /// Each view's settings of a frame drawn with `settings`: a CAVE's walls, or the one panorama.
    fn views(&self, settings: twister::RenderSettings) -> Vec<twister::RenderSettings> {
        if self.walls.is_empty() {
            vec![settings]
        } else {
            self.walls.iter().map(|wall| crate::cave::on_wall(settings, wall)).collect()
        }
    }

    /// Poses an animated scene at `time`.
    fn pose(&mut self, time: f32) -> Result<()> {
        let (renderer, prepared) = (self.renderer, &mut self.prepared);
        if prepared.scene.rig.is_none() {
            return Ok(());
        }
        if self.base.subdivision.method == Method::Trace {
            // The ray tracer's BVH is built on the CPU from the posed vertices.
            prepared.scene.pose(self.clip, time);
            prepared.gpu_scene.update_pose(&renderer.gpu, &prepared.scene)?;
            prepared.gpu_scene.rebuild_bvh(&renderer.gpu, &prepared.scene)
        } else {
            // The skin stage poses the vertices on the GPU; only matrices and weights are uploaded.
            let target = match self.tracked.as_mut() {
                Some(tracked) => &mut tracked.whole,
                None => &mut prepared.gpu_scene,
            };
            renderer.pose(target, &mut prepared.scene, self.clip, time)
        }
    }

    /// The frame's settings: the base's, with the viewer the path or the posed camera puts, and
    /// the tracked head the head path puts.
    fn frame_settings(&self, time: f32) -> twister::RenderSettings {
        let settings = self.viewer_settings(time);
        let Some(path) = &self.head_path else { return settings };
        let v = path.at(time);
        let scale = self.args.view.scale;
        let head = twister::core::panoramas::head::Head::relative(
            Vec3::new(v[0], v[1], v[2]) * scale,
            v.get(3).copied().unwrap_or(self.base_yaw),
            settings.view.viewer,
            settings.view.yaw_deg,
        );
        let projection =
            twister::Projection { head: Some(head), vertical: twister::Vertical::Exact, ..*settings.projection() };
        settings.with_projection(projection)
    }

    /// The frame's settings without the head path's head.
    fn viewer_settings(&self, time: f32) -> twister::RenderSettings {
        let base = self.base;
        if let Some(cam) = self.camera.and_then(|n| self.prepared.scene.cameras.get(n)) {
            return base.with_viewer(Vec3::from(cam.position)).with_yaw_deg(self.base_yaw + cam.yaw_deg);
        }
        match &self.viewer_path {
            Some(path) => {
                let v = path.at(time);
                let yaw = self.base_yaw + v.get(3).copied().unwrap_or(0.0);
                base.with_viewer(Vec3::new(v[0], v[1], v[2]) * self.args.view.scale).with_yaw_deg(yaw)
            }
            None => base,
        }
    }
}

/// What opening a sequence gives: the settings, its views' writers, and the sequence that
/// draws its frames.
pub struct Opened<'a> {
    pub settings: twister::RenderSettings,
    pub writer: FrameWriter,
    pub writers: Vec<FrameWriter>,
    pub stereo: StereoMode,
    sequence: Sequence<'a>,
}

impl Opened<'_> {
    /// Whether a view is larger than the adapter draws at once (`--frames` draws it in tiles,
    /// written as they are drawn).
    pub fn any_tiled(&self) -> bool {
        let s = &self.sequence;
        crate::tiled::any_tiled(s.renderer, &s.views(s.base), s.args.max_tile)
    }

    /// Draws frame `frame`: each view's (a CAVE's walls, or the one panorama) settings and frame;
    /// frames drawn in tiles (already written) are left out.
    pub fn draw(&mut self, frame: u32) -> Result<Vec<(twister::RenderSettings, twister::Frame)>> {
        Ok(self
            .sequence
            .draw(frame)?
            .into_iter()
            .filter(|d| d.written.is_none())
            .map(|d| (d.settings, d.rendered))
            .collect())
    }
}

/// A sequence's options, checked, with its paths read: what opens it, before any device.
pub struct Checked {
    settings: twister::RenderSettings,
    writer: FrameWriter,
    writers: Vec<FrameWriter>,
    stereo: StereoMode,
    walls: Vec<twister::Projection>,
    gaze_path: Option<GazePath>,
    lod: Option<(LodParams, twister::core::detail::visual_field::Gaze)>,
    viewer_path: Option<Timeline>,
    head_path: Option<Timeline>,
}

/// Checks a sequence's options and reads its paths.
pub fn check_sequence(args: &RenderArgs) -> Result<Checked> {
    if let Some(side) = args.max_tile.filter(|&s| s < 16) {
        return Err(Error::option("--max-tile", format!("must be at least 16 pixels, got {side}")));
    }
    let settings = render_settings(args)?;
    check_sequence_options(args)?;
    let writer = FrameWriter::new(args, &settings, true)?;
    let stereo = video_stereo(args, &writer)?;
    // A CAVE: each wall its projection and its writer (files named by wall).
    let walls = args.view.cave_walls(&settings)?;
    if !walls.is_empty() && args.video.is_some() {
        return Err(Error::option("--video", "encodes one panorama: a CAVE's walls are images apart"));
    }
    let writers: Vec<FrameWriter> = if walls.is_empty() {
        vec![writer.clone()]
    } else {
        walls.iter().map(|(name, _)| writer.for_wall(Some(name.clone()))).collect()
    };
    let walls: Vec<twister::Projection> = walls.into_iter().map(|(_, p)| p).collect();
    let gaze_path = args.gaze_path.as_deref().map(GazePath::read).transpose()?;
    let lod = args.view.lod()?;
    let viewer_path = read_viewer_path(args)?;
    let head_path = read_head_path(args, &settings)?;
    if gaze_path.is_some() && lod.is_none() {
        return Err(Error::option("--gaze-path", "steers the level of detail: use it with --lod visual-field"));
    }
    Ok(Checked { settings, writer, writers, stereo, walls, gaze_path, lod, viewer_path, head_path })
}

/// Places and uploads the scene of a checked sequence (`loaded`: already loaded from
/// `args.scene`): what draws its frames.
pub fn open_sequence<'a>(
    args: &'a RenderArgs,
    checked: Checked,
    renderer: &'a twister::Renderer,
    loaded: Option<&twister::Scene>,
) -> Result<Opened<'a>> {
    let Checked { settings, writer, writers, stereo, walls, gaze_path, lod, viewer_path, head_path } = checked;
    let base_yaw = settings.view.yaw_deg;
    let method = [settings.subdivision.method];
    let prepared = prepare_loaded(renderer, &args.scene, loaded, args.fit, &args.view, settings, false, &method)?;
    let clip = animation_clip(args, &prepared.scene)?;
    let tracked = match (gaze_path, &lod) {
        (Some(path), Some((params, _))) => Some(Tracked {
            path,
            params: *params,
            chain: LodChain::build(&prepared.scene, params.p3),
            whole: twister::GpuScene::upload(&renderer.gpu, &prepared.scene)?,
        }),
        _ => None,
    };
    let camera = match args.view.viewer {
        Viewer::Camera(n) => Some(n),
        Viewer::At(_) => None,
    };
    let base = prepared.settings;
    let sequence = Sequence {
        args,
        renderer,
        prepared,
        base,
        base_yaw,
        clip,
        viewer_path,
        head_path,
        camera,
        tracked,
        walls,
        writers: writers.clone(),
    };
    Ok(Opened { settings, writer, writers, stereo, sequence })
}

/// Renders the sequence `args.frames` asks for.
pub fn render_sequence(args: &RenderArgs, (first, last): (u32, u32)) -> Result<()> {
    let frames = match args.shard {
        Some(shard) => shard_frames(first, last, shard, args.shard_mode),
        None => (first..=last).collect(),
    };
    let checked = check_sequence(args)?;
    let (renderer, adapter) = open_renderer()?;
    let Opened { settings, writer, writers, stereo, mut sequence } = open_sequence(args, checked, &renderer, None)?;
    let complete = |f: u32| writers.iter().all(|w| w.paths(Some(f)).iter().all(|p| p.exists()));
    let todo: Vec<u32> = frames.into_iter().filter(|&f| !(args.resume && complete(f))).collect();
    let stats = open_stats(args)?;
    let progress = indicatif::ProgressBar::new(todo.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {per_sec}, ETA {eta}")
            .expect("a valid template"),
    );
    let start = std::time::Instant::now();
    // A writer thread encodes and writes frame k while the GPU draws frame k + 1 (one frame in
    // flight: bounded memory).
    let (send, receive) = std::sync::mpsc::sync_channel::<Drawn>(1);
    std::thread::scope(|scope| -> Result<()> {
        let writing = scope.spawn(|| write_frames(receive, args, &writers, stats, &progress, &adapter));
        let drawn = (|| -> Result<()> {
            for &frame in &todo {
                for drawn in sequence.draw(frame)? {
                    if send.send(drawn).is_err() {
                        return Ok(()); // the writer stopped: its error is reported below
                    }
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
        encode_video(video, &args.out.join(name), first, last - first + 1, args.fps, stereo, settings.projection())?;
        println!("{}", video.display());
    }
    Ok(())
}

/// The writer thread: encodes and writes each drawn frame's files (all of a frame or none) and
/// its `--stats` line.
fn write_frames(
    receive: std::sync::mpsc::Receiver<Drawn>,
    args: &RenderArgs,
    writers: &[FrameWriter],
    mut stats: Option<std::fs::File>,
    progress: &indicatif::ProgressBar,
    adapter: &str,
) -> Result<()> {
    for drawn in receive {
        let writer = &writers[drawn.view];
        let t = std::time::Instant::now();
        let paths: Vec<PathBuf> = match &drawn.written {
            Some(paths) => paths.clone(),
            None => {
                let files = writer.files(&drawn.rendered, Some(drawn.frame))?;
                write_all(&files)?;
                files.into_iter().map(|f| f.path).collect()
            }
        };
        let ms_write = t.elapsed().as_secs_f64() * 1e3;
        if let (Some(file), Some(path)) = (stats.as_mut(), &args.stats) {
            let lod = crate::scene::lod_stats(&drawn.selected);
            let record = FrameRecord {
                frame: Some(drawn.frame),
                time: Some(drawn.time),
                ms_pose: Some(drawn.ms_pose),
                ms_write,
                files: Some(paths.iter().map(|p| p.display().to_string()).collect()),
                ..FrameRecord::new(&args.scene, &drawn.settings, &drawn.rendered, writer, adapter, lod)
            };
            let line = serde_json::to_string(&record).expect("JSON of plain values");
            writeln!(file, "{line}").map_err(|e| Error::output(path, format!("cannot write: {e}")))?;
        }
        if drawn.view + 1 == writers.len() {
            progress.inc(1);
        }
    }
    Ok(())
}

/// The options a sequence refuses (a still's outputs) and its frame rate.
fn check_sequence_options(args: &RenderArgs) -> Result<()> {
    for (given, option) in [(args.depth, "--depth"), (args.hdr, "--hdr"), (args.lod_overlay, "--lod-overlay")] {
        if given {
            return Err(Error::option(option, "writes one still: leave it out with --frames"));
        }
    }
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(Error::option("--fps", format!("must be between 0 and 1000 frames per second, got {}", args.fps)));
    }
    Ok(())
}

/// The stereo mode a video of the layout carries; with `--video`, its conditions checked (one
/// image per frame, PNG, not a shard, ffmpeg installed, the output writable).
fn video_stereo(args: &RenderArgs, writer: &FrameWriter) -> Result<StereoMode> {
    let stereo = match writer.layout() {
        Layout::TopBottom => StereoMode::TopBottom,
        Layout::SideBySide => StereoMode::LeftRight,
        _ => StereoMode::Mono,
    };
    if let Some(video) = &args.video {
        if args.shard.is_some() {
            return Err(Error::option(
                "--video",
                "encodes the whole sequence: render the shards, then run once more with --resume --video",
            ));
        }
        if stereo == StereoMode::Mono {
            return Err(Error::option("--video", "needs a one-image layout: --layout top-bottom or side-by-side"));
        }
        if args.format != twister::output::ImageFormat::Png {
            return Err(Error::option("--video", "encodes the PNG frames: leave --format png"));
        }
        twister::output::check_outputs(&[video.as_path()])?;
        ffmpeg_version()?;
    }
    Ok(stereo)
}

/// `--viewer-path`, read and checked.
fn read_viewer_path(args: &RenderArgs) -> Result<Option<Timeline>> {
    match &args.viewer_path {
        Some(_) if matches!(args.view.viewer, Viewer::Camera(_)) => {
            Err(Error::option("--viewer-path", "moves the viewer itself: leave out --viewer camera"))
        }
        Some(path) => Ok(Some(Timeline::read(path, "viewer_path", (3, 4), "time,x,y,z[,yaw]", |v| {
            let max = twister::core::scenes::scene::MAX_COORDINATE;
            (v[..3].iter().any(|c| c.abs() > max)).then(|| format!("coordinates within ±{max:e}"))
        })?)),
        None => Ok(None),
    }
}

/// `--head-path`, read and checked: the cylinder, the display's centre given as a place, no
/// fixed `--head`, the exact model.
fn read_head_path(args: &RenderArgs, settings: &twister::RenderSettings) -> Result<Option<Timeline>> {
    let Some(path) = &args.head_path else { return Ok(None) };
    let why = if args.view.head.is_some() {
        Some("moves the head itself: leave out --head")
    } else if matches!(args.view.viewer, Viewer::Camera(_)) {
        Some("needs the display's centre as --viewer x,y,z")
    } else if !matches!(settings.projection().panorama, PanoramaKind::Cylinder | PanoramaKind::Cave) {
        Some("a tracked head looks at the cylinder or CAVE walls: use it with --panorama cylinder or cave")
    } else if args.view.vertical == Some(twister::Vertical::Paper) {
        Some("a tracked head draws each point where the line from the eye meets the screen: leave out --vertical paper")
    } else if settings.subdivision.method.name().starts_with("slit") {
        Some("slit pastes the slits of eyes on the circle about the display's centre: use trace as the reference")
    } else {
        None
    };
    if let Some(why) = why {
        return Err(Error::option("--head-path", why));
    }
    Ok(Some(crate::cave::read_head_timeline(path)?))
}

/// The animation a sequence plays: `--animation` by name or index, else the file's first.
pub fn animation_clip(args: &RenderArgs, scene: &twister::Scene) -> Result<Option<usize>> {
    Ok(match (&scene.rig, &args.animation) {
        (Some(rig), Some(name)) => Some(rig.clip_index(name).ok_or_else(|| {
            let known: Vec<&str> = rig.clips.iter().map(|c| c.name.as_str()).collect();
            Error::option("--animation", format!("{name}: the file's animations are {}", known.join(", ")))
        })?),
        (Some(rig), None) => (!rig.clips.is_empty()).then_some(0),
        (None, Some(_)) => return Err(Error::option("--animation", format!("{} has no animations", args.scene))),
        (None, None) => None,
    })
}

/// The `--stats` file: appended to with `--resume`, else written anew.
fn open_stats(args: &RenderArgs) -> Result<Option<std::fs::File>> {
    let Some(path) = &args.stats else { return Ok(None) };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, format!("cannot create the folder: {e}")))?;
    }
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(args.resume)
        .write(true)
        .truncate(!args.resume)
        .open(path)
        .map_err(|e| Error::output(path, format!("cannot write: {e}")))?;
    Ok(Some(file))
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
    projection: &twister::Projection,
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
    let bytes = twister::video::with_spherical_metadata(
        &encoded,
        &name,
        stereo,
        projection.panorama,
        [projection.width, projection.height],
    )?;
    write_all(&[twister::output::OutputFile { path: video.to_path_buf(), bytes }])
}
