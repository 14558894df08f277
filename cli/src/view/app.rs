//! The window (winit) and its surface (wgpu): events to the live state (`live.rs`), a frame per
//! redraw, a resize or a lost surface configured again, a lost device opened again with the
//! same options, closing the window or Escape an exit with 0.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Fullscreen, Window, WindowId};

use super::head_input::HeadInput;
use super::live::{Action, Held, Live, Resume};
use super::{OnOff, ViewCmdArgs};
use twister::error::{Error, Result};
use twister::gpu::display::DisplayTarget;
use twister::gpu::Gpu;
use twister::Renderer;

/// Radians the gaze turns per pixel the mouse is dragged.
const TURN_PER_PX: f32 = 0.005;

struct Shown<'a> {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    live: Live<'a>,
    lost: Arc<AtomicBool>,
}

struct App<'a> {
    args: &'a ViewCmdArgs,
    head: Option<HeadInput>,
    shown: Option<Shown<'a>>,
    error: Option<Error>,
    held: std::collections::HashSet<KeyCode>,
    dragging: bool,
    cursor: Option<(f64, f64)>,
}

/// The window system's absence in one line.
fn no_window_system(e: impl std::fmt::Display) -> Error {
    let var = |v: &str| std::env::var_os(v).filter(|s| !s.is_empty()).map(|s| s.to_string_lossy().into_owned());
    let help = "use `twister render` to write the files instead";
    match (var("DISPLAY"), var("WAYLAND_DISPLAY")) {
        (None, None) => {
            Error::NoGpu(format!("view needs a window system: DISPLAY and WAYLAND_DISPLAY are unset ({help})"))
        }
        (x11, wayland) => {
            // winit's message without the source place it begins with.
            let text = e.to_string();
            let text = text.rsplit_once(".rs:").map_or(text.as_str(), |(_, t)| {
                t.trim_start_matches(|c: char| c.is_ascii_digit() || c == ':' || c == ' ')
            });
            let on = x11
                .map(|d| format!("DISPLAY '{d}'"))
                .or(wayland.map(|d| format!("WAYLAND_DISPLAY '{d}'")))
                .unwrap_or_default();
            Error::NoGpu(format!("view cannot open a window on {on}: {} ({help})", text.trim_end_matches('.')))
        }
    }
}

pub fn run(args: &ViewCmdArgs, head: Option<HeadInput>) -> Result<()> {
    let event_loop = EventLoop::new().map_err(no_window_system)?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App { args, head, shown: None, error: None, held: Default::default(), dragging: false, cursor: None };
    event_loop.run_app(&mut app).map_err(no_window_system)?;
    if let Some(shown) = app.shown.as_mut() {
        shown.live.finish();
    }
    app.error.map_or(Ok(()), Err)
}

/// The window's first size: the panoramas at their own size where the screen holds them, else
/// scaled to 90 % of it.
fn first_size(content: [u32; 2], screen: Option<PhysicalSize<u32>>) -> PhysicalSize<u32> {
    let screen = screen.unwrap_or(PhysicalSize::new(1920, 1080));
    let (sw, sh) = (screen.width as f32 * 0.9, screen.height as f32 * 0.9);
    let scale = (sw / content[0] as f32).min(sh / content[1] as f32).min(1.0);
    PhysicalSize::new(((content[0] as f32 * scale) as u32).max(64), ((content[1] as f32 * scale) as u32).max(64))
}

impl<'a> App<'a> {
    fn open(&mut self, el: &ActiveEventLoop) -> Result<Shown<'a>> {
        let settings = crate::render::render_settings(&self.args.render)?;
        let p = settings.projection();
        let monitors: Vec<_> = el.available_monitors().collect();
        let mut attributes = Window::default_attributes().with_title("twister view");
        match self.args.monitor {
            Some(n) => {
                let monitor = monitors.get(n).cloned().ok_or_else(|| {
                    let count = monitors.len();
                    let s = if count == 1 { "" } else { "s" };
                    Error::option(
                        "--monitor",
                        format!("{n}: this window system has {count} monitor{s}, numbered from 0"),
                    )
                })?;
                // The monitor's place and size as well: without a window manager to make it
                // fullscreen, the window still covers the monitor.
                attributes = attributes
                    .with_position(monitor.position())
                    .with_inner_size(monitor.size())
                    .with_fullscreen(Some(Fullscreen::Borderless(Some(monitor))));
            }
            None => {
                let screen = el.primary_monitor().or_else(|| monitors.first().cloned()).map(|m| m.size());
                attributes = attributes.with_inner_size(first_size([p.width, 2 * p.height], screen));
            }
        }
        let window = Arc::new(el.create_window(attributes).map_err(no_window_system)?);
        let head = self.head.take();
        self.attach(el, window, Resume::Start(head))
    }

    /// A device and surface for `window`, and the live state on them: from the options, or
    /// resumed where a lost device left it.
    fn attach(&mut self, el: &ActiveEventLoop, window: Arc<Window>, resume: Resume) -> Result<Shown<'a>> {
        let (gpu, surface) = Gpu::for_window(Box::new(el.owned_display_handle()), window.clone())?;
        let lost = Arc::new(AtomicBool::new(false));
        let flag = lost.clone();
        gpu.device.set_device_lost_callback(move |_, _| flag.store(true, Ordering::Relaxed));
        let caps = surface.get_capabilities(&gpu.adapter);
        // A target that stores the bytes as given (the frame's sRGB bytes shown as they are).
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm))
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| Error::NoGpu(format!("the adapter '{}' cannot present to this window", gpu.info.name)))?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: Default::default(),
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: match self.args.vsync {
                OnOff::On => wgpu::PresentMode::AutoVsync,
                OnOff::Off => wgpu::PresentMode::AutoNoVsync,
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        surface.configure(&gpu.device, &config);
        let renderer = Renderer::new(gpu)?;
        let live = Live::new(self.args, renderer, resume)?;
        Ok(Shown { window, surface, config, live, lost })
    }

    fn held(&self) -> Held {
        let on = |k: &[KeyCode]| k.iter().any(|k| self.held.contains(k)) as i32 as f32;
        Held {
            forward: on(&[KeyCode::KeyW, KeyCode::ArrowUp]) - on(&[KeyCode::KeyS, KeyCode::ArrowDown]),
            right: on(&[KeyCode::KeyD, KeyCode::ArrowRight]) - on(&[KeyCode::KeyA, KeyCode::ArrowLeft]),
            up: on(&[KeyCode::KeyE, KeyCode::PageUp]) - on(&[KeyCode::KeyQ, KeyCode::PageDown]),
        }
    }

    fn redraw(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let held = self.held();
        let Some(shown) = self.shown.as_mut() else { return Ok(()) };
        let texture = match shown.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => return Ok(()),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                shown.surface.configure(&shown.live.gpu().device, &shown.config);
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(Error::Gpu("the window's surface could not give a frame".into()))
            }
        };
        let view = texture.texture.create_view(&Default::default());
        let mut enc = shown.live.gpu().device.create_command_encoder(&Default::default());
        let size = [shown.config.width, shown.config.height];
        let target = DisplayTarget { view: &view, format: shown.config.format };
        shown.live.frame(held, &mut enc, target, size, shown.config.format.is_srgb())?;
        let t = Instant::now();
        let queue = &shown.live.gpu().queue;
        queue.submit([enc.finish()]);
        queue.present(texture);
        shown.live.presented(t.elapsed().as_secs_f64() * 1e3);
        if self.args.exit_after > 0 && shown.live.frames >= self.args.exit_after {
            el.exit();
        }
        Ok(())
    }

    fn fail(&mut self, el: &ActiveEventLoop, e: Error) {
        // A lost device: opened again, on the same window, with the state the window had. (A
        // poll runs the device's callbacks: the lost one may not have run yet.)
        if let Some(s) = &self.shown {
            let _ = s.live.gpu().device.poll(wgpu::PollType::Poll);
        }
        let lost = self.shown.as_ref().is_some_and(|s| s.lost.load(Ordering::Relaxed));
        if let Some(mut shown) = self.shown.take_if(|_| lost) {
            eprintln!("warning: the GPU device was lost ({e}); opening it again");
            let (window, resume) = (shown.window.clone(), shown.live.resume());
            drop(shown);
            match self.attach(el, window, resume) {
                Ok(s) => {
                    self.shown = Some(s);
                    return;
                }
                Err(again) => self.error = Some(again),
            }
        } else {
            self.error = Some(e);
        }
        el.exit();
    }

    fn key(&mut self, el: &ActiveEventLoop, code: KeyCode, state: ElementState) -> Result<()> {
        if state == ElementState::Released {
            self.held.remove(&code);
            return Ok(());
        }
        let repeat = !self.held.insert(code);
        let action = match code {
            KeyCode::Escape => {
                el.exit();
                return Ok(());
            }
            KeyCode::KeyM => Action::CycleMethod,
            KeyCode::KeyP => Action::CyclePanorama,
            KeyCode::KeyN => Action::CycleSamples,
            KeyCode::KeyV => Action::CycleShow,
            KeyCode::KeyO => Action::ToggleOverlay,
            KeyCode::Space => Action::TogglePlay,
            KeyCode::F12 | KeyCode::Enter => Action::Save,
            // Test hook (TWISTER_VIEW_TEST_KEYS=1): F9 destroys the device, as a driver reset
            // would lose it.
            KeyCode::F9 if std::env::var("TWISTER_VIEW_TEST_KEYS").is_ok_and(|v| v == "1") => {
                if let Some(s) = &self.shown {
                    s.live.gpu().device.destroy();
                }
                return Ok(());
            }
            KeyCode::F11 => {
                if let Some(s) = &self.shown {
                    let full = s.window.fullscreen().is_none().then_some(Fullscreen::Borderless(None));
                    s.window.set_fullscreen(full);
                }
                return Ok(());
            }
            _ => return Ok(()),
        };
        match self.shown.as_mut() {
            Some(s) if !repeat => s.live.act(action),
            _ => Ok(()),
        }
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.shown.is_some() {
            return;
        }
        match self.open(el) {
            Ok(shown) => {
                shown.window.request_redraw();
                self.shown = Some(shown);
            }
            Err(e) => {
                self.error = Some(e);
                el.exit();
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let result = match event {
            // Closed by the window manager, or destroyed: the window's work is done.
            WindowEvent::CloseRequested | WindowEvent::Destroyed => {
                el.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                if let Some(s) = self.shown.as_mut().filter(|_| size.width > 0 && size.height > 0) {
                    (s.config.width, s.config.height) = (size.width, size.height);
                    s.surface.configure(&s.live.gpu().device, &s.config);
                }
                Ok(())
            }
            WindowEvent::RedrawRequested => self.redraw(el),
            WindowEvent::KeyboardInput { event, .. } => match event.physical_key {
                PhysicalKey::Code(code) => self.key(el, code, event.state),
                PhysicalKey::Unidentified(_) => Ok(()),
            },
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                self.dragging = state == ElementState::Pressed;
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                let last = self.cursor.replace((position.x, position.y));
                match (self.dragging, last, self.shown.as_mut()) {
                    (true, Some((x, y)), Some(s)) => {
                        s.live.turn((position.x - x) as f32 * TURN_PER_PX, -(position.y - y) as f32 * TURN_PER_PX)
                    }
                    _ => Ok(()),
                }
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(el, e);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(s) = &self.shown {
            s.window.request_redraw();
        }
    }
}
