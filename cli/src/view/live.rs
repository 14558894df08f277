//! The window's state between frames: the options as `render` would take them (changed by the
//! keys, the mouse and the head input), the placed scene, the clock, and each frame drawn with
//! the renderer and shown by the display stage.

use std::time::Instant;

use glam::{Mat3, Vec3};

use super::head_input::HeadInput;
use super::{OnOff, Show, ViewCmdArgs};
use crate::args::{RenderArgs, Viewer};
use crate::render::render_settings;
use crate::scene::{prepare, Prepared};
use twister::core::detail::visual_field::Gaze;
use twister::core::display::{DisplayView, Look};
use twister::core::panoramas::projection::PanoramaKind;
use twister::core::settings::{Method, Split};
use twister::error::{Error, Result};
use twister::gpu::display::{DisplayTarget, ShownFrame};
use twister::{EyeImage, RenderSettings, Renderer};

/// The methods the M key cycles through, and the panoramas of the P key.
fn methods() -> [Method; 5] {
    [Method::Adaptive(Split::default()), Method::Vertex, Method::Fixed(8), Method::Slit(4), Method::Trace]
}
const PANORAMAS: [PanoramaKind; 5] =
    [PanoramaKind::Cylinder, PanoramaKind::Equirect, PanoramaKind::Vr180, PanoramaKind::Fisheye, PanoramaKind::Cubemap];
const SAMPLES: [u32; 4] = [1, 4, 8, 16];

/// Keys held down: the move directions (forward, right, up), each −1, 0 or 1.
#[derive(Clone, Copy, Debug, Default)]
pub struct Held {
    pub forward: f32,
    pub right: f32,
    pub up: f32,
}

/// What a key asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    CycleMethod,
    CyclePanorama,
    CycleSamples,
    CycleShow,
    ToggleOverlay,
    TogglePlay,
    Save,
}

/// Frames per second over the last second.
#[derive(Default)]
struct Meter {
    times: std::collections::VecDeque<Instant>,
}

impl Meter {
    fn tick(&mut self, now: Instant) -> f64 {
        self.times.push_back(now);
        while self.times.len() > 2 && now.duration_since(self.times[0]).as_secs_f64() > 1.0 {
            self.times.pop_front();
        }
        let span = now.duration_since(self.times[0]).as_secs_f64();
        if span > 0.0 {
            (self.times.len() - 1) as f64 / span
        } else {
            0.0
        }
    }
}

/// How the live state starts: from the options (with the head input), or where a lost device
/// left it.
pub enum Resume {
    Start(Option<HeadInput>),
    Lost(Box<Kept>),
}

/// The state a lost device's window goes on with.
pub struct Kept {
    args: RenderArgs,
    look: Look,
    show: Show,
    overlay_on: bool,
    anim_frame: u64,
    head: Option<HeadInput>,
}

pub struct Live<'a> {
    pub opts: &'a ViewCmdArgs,
    /// The options a saved frame is rendered with (`render`'s), as the window has them now.
    pub args: RenderArgs,
    renderer: Renderer,
    prepared: Prepared,
    settings: RenderSettings,
    /// The gaze of the look-around and the level of detail: yaw to the right, pitch up (radians).
    pub look: Look,
    pub show: Show,
    pub overlay_on: bool,
    clip: Option<usize>,
    playing: bool,
    /// The animation's frame (at `--fps`): the pose drawn.
    anim_frame: u64,
    anim_clock: f64,
    start: Instant,
    last: Instant,
    head: Option<HeadInput>,
    meter: Meter,
    pub frames: u64,
    /// The last frame's statistics and the overlay's message.
    stats: twister::FrameStats,
    message: String,
    fps: f64,
    ms_present: f64,
    overlay: Option<([u32; 2], wgpu::Buffer)>,
    overlay_at: Option<Instant>,
    saves: Vec<std::thread::JoinHandle<Result<()>>>,
    /// With `--lod visual-field`: the scene's chains and the whole scene uploaded.
    lod: Option<(twister::core::detail::lod::LodChain, twister::GpuScene)>,
}

impl<'a> Live<'a> {
    pub fn new(opts: &'a ViewCmdArgs, renderer: Renderer, resume: Resume) -> Result<Live<'a>> {
        let (head, state) = match resume {
            Resume::Start(head) => (head, None),
            Resume::Lost(state) => {
                (state.head, Some((state.args, state.look, state.show, state.overlay_on, state.anim_frame)))
            }
        };
        let mut args = state.as_ref().map_or_else(|| opts.render.clone(), |s| s.0.clone());
        let settings = render_settings(&args)?;
        let prepared = prepare_for(&renderer, &args, settings)?;
        // A file camera's place becomes the viewer the keys move (the same frame).
        let placed = prepared.settings;
        args.view.viewer = Viewer::At(placed.view.viewer / args.view.scale);
        args.view.yaw = placed.view.yaw_deg;
        let clip = crate::sequence::animation_clip(&args, &prepared.scene)?;
        let now = Instant::now();
        let mut live = Live {
            opts,
            settings: render_settings(&args)?,
            args,
            renderer,
            prepared,
            look: Look::default(),
            show: opts.show,
            overlay_on: opts.overlay == OnOff::On,
            clip,
            playing: false,
            anim_frame: 0,
            anim_clock: 0.0,
            start: now,
            last: now,
            head,
            meter: Meter::default(),
            frames: 0,
            stats: Default::default(),
            message: String::new(),
            fps: 0.0,
            ms_present: 0.0,
            overlay: None,
            overlay_at: None,
            saves: Vec::new(),
            lod: None,
        }
        .with_lod()?;
        // A clip asked for is shown posed from its first frame (as `render --frames 0` poses it).
        if live.args.animation.is_some() {
            live.pose()?;
        }
        if let Some((_, look, show, overlay_on, anim_frame)) = state {
            (live.look, live.show, live.overlay_on, live.anim_frame) = (look, show, overlay_on, anim_frame);
            live.anim_clock = anim_frame as f64 / live.args.fps as f64;
            live.pose()?;
        }
        Ok(live)
    }

    /// What a device lost takes to the next: the options, the gaze, the display, the pose, the
    /// head input.
    pub fn resume(&mut self) -> Resume {
        Resume::Lost(Box::new(Kept {
            args: self.args.clone(),
            look: self.look,
            show: self.show,
            overlay_on: self.overlay_on,
            anim_frame: self.anim_frame,
            head: self.head.take(),
        }))
    }

    /// With `--lod visual-field`, what the gaze's selection is made from.
    fn with_lod(mut self) -> Result<Live<'a>> {
        if let Some((params, _)) = self.args.view.lod()? {
            let chain = twister::core::detail::lod::LodChain::build(&self.prepared.scene, params.p3);
            let whole = twister::GpuScene::upload(&self.renderer.gpu, &self.prepared.scene)?;
            self.lod = Some((chain, whole));
        }
        Ok(self)
    }

    /// The device the window draws with.
    pub fn gpu(&self) -> &twister::gpu::Gpu {
        &self.renderer.gpu
    }

    fn viewer(&self) -> Vec3 {
        match self.args.view.viewer {
            Viewer::At(p) => p,
            Viewer::Camera(_) => Vec3::ZERO,
        }
    }

    /// The options changed: the settings again, the scene placed again where they place it.
    fn changed(&mut self, replace_scene: bool) -> Result<()> {
        let settings = render_settings(&self.args)?;
        if replace_scene {
            self.prepared = prepare_for(&self.renderer, &self.args, settings)?;
            self.clip = crate::sequence::animation_clip(&self.args, &self.prepared.scene)?;
            self.pose()?;
        } else if let (Some((params, gaze)), Some((chain, whole))) = (self.args.view.lod()?, &self.lod) {
            // The level of detail follows the gaze (seed 001's tracked viewer), as a sequence's
            // gaze path.
            let selection = chain.select(&self.prepared.scene, settings.view(), &gaze, &params);
            self.prepared.gpu_scene = whole.with_lod(&self.renderer.gpu, &selection);
            self.prepared.selection = Some(selection);
        }
        self.settings = settings;
        Ok(())
    }

    /// Tries options; kept if they make valid settings, else the message says why.
    fn try_args(&mut self, args: RenderArgs, replace_scene: bool) -> bool {
        let old = std::mem::replace(&mut self.args, args);
        match self.changed(replace_scene) {
            Ok(()) => true,
            Err(e) => {
                self.message = crate::flags::for_user(e).to_string();
                self.args = old;
                false
            }
        }
    }

    pub fn act(&mut self, action: Action) -> Result<()> {
        self.message.clear();
        match action {
            Action::CycleMethod => {
                let all = methods();
                let at = all.iter().position(|m| m.name() == self.args.view.method.name()).unwrap_or(0);
                for k in 1..=all.len() {
                    let mut args = self.args.clone();
                    args.view.method = all[(at + k) % all.len()];
                    let trace_changes = (args.view.method == Method::Trace) != (self.args.view.method == Method::Trace);
                    if self.try_args(args, trace_changes) {
                        break;
                    }
                }
            }
            Action::CyclePanorama => {
                let now = self.settings.projection().panorama;
                let at = PANORAMAS.iter().position(|&p| p == now).unwrap_or(0);
                for k in 1..=PANORAMAS.len() {
                    let mut args = self.args.clone();
                    let next = PANORAMAS[(at + k) % PANORAMAS.len()];
                    args.view.panorama = Some(next);
                    // The width asked for (or the preset's), each panorama its own aspect (the
                    // cubemap's width a multiple of 3); the cylinder its height asked for.
                    let given = &self.opts.render.view;
                    let width = given.width.or(given.preset.map(|p| p.width()));
                    args.view.width = width.map(|w| if next == PanoramaKind::Cubemap { (w / 3 * 3).max(3) } else { w });
                    args.view.height = if next == PanoramaKind::Cylinder { given.height } else { None };
                    args.view.preset = None;
                    if args.view.panorama != Some(PanoramaKind::Cylinder) {
                        args.view.head = None;
                    }
                    if self.try_args(args, self.args.fit.is_some()) {
                        break;
                    }
                }
            }
            Action::CycleSamples => {
                let n = self.settings.shading.samples;
                let at = SAMPLES.iter().position(|&s| s == n).unwrap_or(0);
                let mut args = self.args.clone();
                args.view.samples = Some(SAMPLES[(at + 1) % SAMPLES.len()]);
                self.try_args(args, false);
            }
            Action::CycleShow => {
                let at = Show::ALL.iter().position(|&s| s == self.show).unwrap_or(0);
                self.show = Show::ALL[(at + 1) % Show::ALL.len()];
            }
            Action::ToggleOverlay => self.overlay_on = !self.overlay_on,
            Action::TogglePlay => {
                if self.prepared.scene.rig.is_some() {
                    self.playing = !self.playing;
                } else {
                    self.message = "the scene has no animation".into();
                }
            }
            Action::Save => self.save(),
        }
        self.overlay_at = None;
        Ok(())
    }

    /// Turns the gaze by (dx, dy) radians (right, up).
    pub fn turn(&mut self, dx: f32, dy: f32) -> Result<()> {
        let limit = 89f32.to_radians();
        self.look.yaw =
            (self.look.yaw + dx + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
        self.look.pitch = (self.look.pitch + dy).clamp(-limit, limit);
        if self.args.view.lod != crate::args::LodMode::Off {
            self.args.view.gaze = Some(Gaze::new(-self.look.yaw.to_degrees(), self.look.pitch.to_degrees()));
            self.changed(false)?;
        }
        Ok(())
    }

    /// Moves the viewer (or the tracked head) by the keys held for `dt` seconds, along the gaze's
    /// horizontal direction.
    fn step(&mut self, held: Held, dt: f32) -> Result<()> {
        if held.forward == 0.0 && held.right == 0.0 && held.up == 0.0 {
            return Ok(());
        }
        // The gaze's directions in the viewer frame, then the scene's (turned by the yaw).
        let y = self.look.yaw;
        let (forward, right) = (Vec3::new(y.sin(), 0.0, -y.cos()), Vec3::new(y.cos(), 0.0, y.sin()));
        let to_scene = Mat3::from_rotation_y(self.args.view.yaw.to_radians());
        let d = to_scene * (forward * held.forward + right * held.right) + Vec3::Y * held.up;
        let delta = d * self.opts.speed * dt;
        match &mut self.args.view.head {
            Some((head, _)) => *head += delta,
            None => self.args.view.viewer = Viewer::At(self.viewer() + delta),
        }
        self.changed(false)
    }

    /// The head input's latest due line: the head where the panorama takes one, else the
    /// viewer; and the gaze.
    fn follow_head(&mut self) -> Result<()> {
        let t = self.start.elapsed().as_secs_f64();
        let Some(sample) = self.head.as_mut().map(|h| h.due(t)).transpose()?.flatten() else { return Ok(()) };
        if self.settings.projection().panorama == PanoramaKind::Cylinder {
            self.args.view.head = Some((sample.position, Some(sample.yaw)));
        } else {
            self.args.view.viewer = Viewer::At(sample.position);
            self.args.view.yaw = sample.yaw;
        }
        // The gaze straight along the head (yaw left-positive as --yaw), pitched.
        let relative = (sample.yaw - self.args.view.yaw).to_radians();
        self.look.yaw = -relative;
        self.look.pitch = sample.pitch.to_radians();
        if self.args.view.lod != crate::args::LodMode::Off {
            self.args.view.gaze = Some(Gaze::new(relative.to_degrees(), sample.pitch));
        }
        self.changed(false)
    }

    /// Poses an animated scene at its frame's time (as `render --frames` does).
    fn pose(&mut self) -> Result<()> {
        if self.prepared.scene.rig.is_none() {
            return Ok(());
        }
        let t = self.anim_frame as f32 / self.args.fps;
        let prepared = &mut self.prepared;
        if self.args.view.method == Method::Trace {
            prepared.scene.pose(self.clip, t);
            prepared.gpu_scene.update_pose(&self.renderer.gpu, &prepared.scene)?;
            prepared.gpu_scene.rebuild_bvh(&self.renderer.gpu, &prepared.scene)
        } else {
            self.renderer.pose(&mut prepared.gpu_scene, &mut prepared.scene, self.clip, t)
        }
    }

    /// Saves the current frame: `render` itself with the window's options, on its own thread
    /// (the window goes on drawing); an animated scene's posed frame as `render --frames K`.
    fn save(&mut self) {
        let mut args = self.args.clone();
        // `--animation` belongs to a sequence for `render`: frame K of it, even frame 0.
        let posed = self.prepared.scene.rig.is_some() && (self.anim_frame > 0 || args.animation.is_some());
        if posed {
            args.frames = Some((self.anim_frame as u32, self.anim_frame as u32));
        }
        self.message = format!("saving into {}", args.out.display());
        self.saves.push(std::thread::spawn(move || match args.frames {
            Some(frames) => crate::sequence::render_sequence(&args, frames),
            None => crate::render::render(&args),
        }));
    }

    /// Saves finished: their errors (the window goes on).
    fn saved(&mut self) {
        let (done, running): (Vec<_>, Vec<_>) = self.saves.drain(..).partition(|h| h.is_finished());
        self.saves = running;
        for handle in done {
            self.message = match handle.join() {
                Ok(Ok(())) => format!("saved into {}", self.args.out.display()),
                Ok(Err(e)) => format!("not saved: {}", crate::flags::for_user(e)),
                Err(_) => "not saved: the save stopped".into(),
            };
            eprintln!("{}", self.message);
        }
    }

    /// Waits for the saves still running (the window is closing).
    pub fn finish(&mut self) {
        for handle in self.saves.drain(..) {
            if let Ok(Err(e)) = handle.join() {
                eprintln!("error: {}", crate::flags::for_user(e));
            }
        }
    }

    /// Advances the clock, follows the input, draws the frame and records its display into
    /// `target` (`size` its pixels).
    pub fn frame(
        &mut self,
        held: Held,
        enc: &mut wgpu::CommandEncoder,
        target: DisplayTarget,
        size: [u32; 2],
        srgb: bool,
    ) -> Result<()> {
        let now = Instant::now();
        let dt = now.duration_since(self.last).as_secs_f64().min(0.25);
        self.last = now;
        self.saved();
        self.follow_head()?;
        self.step(held, dt as f32)?;
        if self.playing {
            self.anim_clock += dt;
            let frame = (self.anim_clock * self.args.fps as f64) as u64;
            if frame != self.anim_frame {
                self.anim_frame = frame;
                self.pose()?;
            }
        }
        let settings = self.settings;
        let shown = if self.show == Show::Heatmap {
            let frame = self.renderer.render(&self.prepared.gpu_scene, &settings.with_measure_error(true))?;
            let m = frame.measurement.as_ref().ok_or_else(|| Error::Gpu("the error pass measured nothing".into()))?;
            let p = settings.projection();
            let (w, h, rgba) =
                crate::heatmap::heatmap(&m.error, p.width, p.height, crate::heatmap::nice_max(m.stats.p99));
            self.stats = frame.stats;
            ShownFrame::upload(&self.renderer.gpu, &[&EyeImage { width: w, height: h, rgba }])
        } else {
            let (frame, shown) = self.renderer.render_shown(&self.prepared.gpu_scene, &settings)?;
            self.stats = frame.stats;
            shown
        };
        self.frames += 1;
        self.fps = self.meter.tick(Instant::now());
        self.update_overlay(now);
        let view = DisplayView {
            mode: self.show.mode(),
            look: self.look,
            image: [shown.width, shown.height],
            layers: shown.layers,
            row_texels: shown.row_texels,
            target: size,
            overlay: self.overlay.as_ref().filter(|_| self.overlay_on).map(|([w, h], _)| [8, 8, *w, *h]),
            srgb_target: srgb,
        };
        let params = twister::encoding::params::display_params(&view, settings.projection());
        let overlay = self.overlay.as_ref().filter(|_| self.overlay_on).map(|(_, b)| b);
        self.renderer.display().draw(&self.renderer.gpu, enc, target, &params, &shown, overlay);
        if self.opts.trace_frames {
            println!("{}", self.trace_line());
        }
        Ok(())
    }

    /// The time presenting took (the overlay shows it).
    pub fn presented(&mut self, ms: f64) {
        self.ms_present = ms;
    }

    /// A shown frame in one line (`--trace-frames`): what a script needs to render it again
    /// (the look-around's gaze in radians, as the display stage takes it).
    fn trace_line(&self) -> String {
        let v = self.viewer();
        let head = self.args.view.head.map_or(String::new(), |(h, yaw)| {
            format!(" head={},{},{},{}", h.x, h.y, h.z, yaw.unwrap_or(self.args.view.yaw))
        });
        // Resident memory (Linux: /proc/self/statm's second field, pages of 4 KiB).
        let rss = std::fs::read_to_string("/proc/self/statm")
            .ok()
            .and_then(|s| s.split_whitespace().nth(1).and_then(|p| p.parse::<u64>().ok()))
            .map_or("-".to_string(), |pages| format!("{:.1}", pages as f64 * 4096.0 / (1 << 20) as f64));
        format!(
            "frame {} fps={:.2} ms_render={:.1} rss_mib={rss} triangles={} gaze={},{} viewer={},{},{} yaw={}{head} look={},{} method={} panorama={:?} samples={} show={} anim_frame={}",
            self.frames,
            self.fps,
            self.stats.ms_total,
            self.stats.triangles_out,
            -self.look.yaw.to_degrees(),
            self.look.pitch.to_degrees(),
            v.x,
            v.y,
            v.z,
            self.args.view.yaw,
            self.look.yaw,
            self.look.pitch,
            self.args.view.method.name(),
            self.settings.projection().panorama,
            self.settings.shading.samples,
            self.show.name(),
            self.anim_frame,
        )
    }

    /// The overlay's text, made again four times a second (or when something changed).
    fn update_overlay(&mut self, now: Instant) {
        if !self.overlay_on || self.overlay_at.is_some_and(|t| now.duration_since(t).as_secs_f64() < 0.25) {
            return;
        }
        self.overlay_at = Some(now);
        let s = &self.stats;
        let p = self.settings.projection();
        let ms = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
        let v = self.viewer();
        let mut lines = vec![
            format!("{:.1} fps  frame {:.1} ms", self.fps, s.ms_total),
            format!(
                "subdivide {} ms  raster {} ms  present {:.1} ms",
                ms(s.ms_subdivide),
                ms(s.ms_raster),
                self.ms_present
            ),
            format!("{} triangles out", s.triangles_out),
            format!(
                "{}  {:?} {}x{}  {} sample{}",
                self.args.view.method.name(),
                p.panorama,
                p.width,
                p.height,
                s.samples,
                if s.samples == 1 { "" } else { "s" }
            ),
            format!("viewer {:.2},{:.2},{:.2}  yaw {:.0}  {}", v.x, v.y, v.z, self.args.view.yaw, self.show.name()),
            "WASD/QE move, drag turn, M method, P panorama".into(),
            "N samples, V display, space play, F12 save, O overlay".into(),
        ];
        if !self.message.is_empty() {
            lines.push(self.message.chars().take(100).collect());
        }
        let (size, texels) = super::overlay::overlay(&lines);
        let buffer =
            self.renderer.gpu.init_buffer("overlay", bytemuck::cast_slice(&texels), wgpu::BufferUsages::STORAGE);
        self.overlay = Some((size, buffer));
    }
}

/// Places and uploads the scene for `args` (as `render` does).
fn prepare_for(renderer: &Renderer, args: &RenderArgs, settings: RenderSettings) -> Result<Prepared> {
    let method = [settings.subdivision.method];
    prepare(renderer, &args.scene, args.fit, &args.view, settings, args.lod_overlay, &method)
}
