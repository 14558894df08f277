//! `twister view`: the live window (issue 35). Every frame is drawn by the same renderer, with
//! the same settings and placed scene as `render` (`render::render_settings`, `scene::prepare`),
//! its colour kept on the GPU and shown by the display stage (`core::display`): the panoramas,
//! the TWISTER display's four halves, a look-around preview (side by side or anaglyph), or the
//! error heatmap of the current method. Keys move the viewer and cycle the method, panorama,
//! samples and display; `--head-input` moves the head as a tracker's lines arrive; a key saves
//! the current frame by running `render` itself with the window's settings (same bytes), on a
//! thread of its own so that the window never waits on the disk.

mod app;
mod head_input;
mod live;
mod overlay;

use std::path::PathBuf;

use clap::Args;

use crate::args::RenderArgs;
use twister::core::display::DisplayMode;
use twister::error::{Error, Result};

/// The display a window starts with (`--show`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Show {
    /// Both eyes' panoramas, left above right.
    Panorama,
    /// The TWISTER display's four halves (front, back; left eye on top), filling the screen.
    Halves,
    /// A perspective look-around into each eye's panorama, side by side (as a headset shows it).
    Look,
    /// The look-around as a red-cyan anaglyph.
    Anaglyph,
    /// The display-position error of the current method, colour-mapped (as `error --heatmap`).
    Heatmap,
}

impl Show {
    pub const ALL: [Show; 5] = [Show::Panorama, Show::Halves, Show::Look, Show::Anaglyph, Show::Heatmap];

    /// The display stage's mode (the heatmap is one image shown as a panorama).
    pub fn mode(self) -> DisplayMode {
        match self {
            Show::Panorama | Show::Heatmap => DisplayMode::Panorama,
            Show::Halves => DisplayMode::Halves,
            Show::Look => DisplayMode::LookSideBySide,
            Show::Anaglyph => DisplayMode::LookAnaglyph,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Show::Heatmap => "error heatmap",
            s => s.mode().name(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

/// `twister view`'s options: `render`'s (what a saved frame is written with), and the window's.
#[derive(Args)]
pub struct ViewCmdArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// What the window shows first (keys: V cycles).
    #[arg(long, value_enum, default_value_t = Show::Panorama)]
    pub show: Show,
    /// Wait for the monitor's refresh before each frame is shown.
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub vsync: OnOff,
    /// Fullscreen on this monitor (0 the first; the TWISTER display's output) instead of a window.
    #[arg(long, value_name = "N")]
    pub monitor: Option<usize>,
    /// The tracked head: lines of time,x,y,z,yaw,pitch (seconds; scene units as --head or
    /// --viewer; degrees) from a file or `-` (standard input), applied when the window's clock
    /// reaches their time (as they arrive from a pipe). x, y, z and yaw place the head where the
    /// panorama takes one (--head), else the viewer; yaw and pitch turn the gaze.
    #[arg(long, value_name = "FILE|-")]
    pub head_input: Option<PathBuf>,
    /// Show the overlay (frames per second, the frame's time split, triangles, method; key O).
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub overlay: OnOff,
    /// Move speed, scene units per second (W/A/S/D, arrows, Q/E).
    #[arg(long, default_value_t = 1.0, value_name = "UNITS")]
    pub speed: f32,
    /// Close after this many frames (scripts, benchmarks; 0: never).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub exit_after: u64,
    /// Write a line per shown frame to standard output: its number, viewer, yaw, gaze, method,
    /// panorama, samples, display (scripts and tests follow the window with it).
    #[arg(long)]
    pub trace_frames: bool,
}

/// Opens the window and runs it until it is closed.
pub fn view(args: &ViewCmdArgs) -> Result<()> {
    let r = &args.render;
    for (given, option) in [
        (r.frames.is_some(), "--frames"),
        (r.resume, "--resume"),
        (r.shard.is_some(), "--shard"),
        (r.video.is_some(), "--video"),
        (r.gaze_path.is_some(), "--gaze-path"),
        (r.viewer_path.is_some(), "--viewer-path"),
        (r.head_path.is_some(), "--head-path"),
        (r.max_tile.is_some(), "--max-tile"),
        (r.stats.is_some(), "--stats"),
    ] {
        if given {
            return Err(Error::option(option, "belongs to `render`: the window draws one frame at a time"));
        }
    }
    if r.view.cave.is_some() || r.view.panorama == Some(twister::core::panoramas::projection::PanoramaKind::Cave) {
        return Err(Error::option(
            "--cave",
            "a CAVE's walls are images apart: render them (the window shows one panorama)",
        ));
    }
    if !(args.speed.is_finite() && args.speed > 0.0) {
        return Err(Error::option(
            "--speed",
            format!("must be a positive number of scene units per second, got {}", args.speed),
        ));
    }
    // Settings are checked before a window opens (one line, as `render`'s).
    crate::render::render_settings(r)?;
    let head_input = args.head_input.as_deref().map(head_input::HeadInput::open).transpose()?;
    app::run(args, head_input)
}
