//! `twister view`, the live window, as a user runs it: under a virtual X server (Xvfb) with the
//! software driver, its screen grabbed by ffmpeg and keys sent by xdotool (scripts/test.sh
//! installs them). The window must show exactly what `render` draws for the same settings,
//! move the viewer as the keys and the head input say, and save the frame `render` writes,
//! byte for byte. Without Xvfb or xdotool these tests say so and pass, except under CI.

mod common;

use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use common::twister;
use twister::core::display::{DisplayMode, DisplayView, Look};
use twister::cpu::display::display;
use twister::Projection;

const SIZE: [&str; 4] = ["--width", "128", "--height", "32"];
/// The cylinder the windows draw (SIZE).
fn cylinder() -> Projection {
    Projection { width: 128, height: 32, ..Projection::default() }
}

fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(format!("twister-view-{}-{name}", std::process::id()))
}

fn have(tool: &str) -> bool {
    Command::new("sh").args(["-c", &format!("command -v {tool}")]).output().is_ok_and(|o| o.status.success())
}

/// A virtual X server on a display of its own, stopped when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// None (the test does not run) where Xvfb, xdotool or ffmpeg is missing; under CI a
    /// missing tool fails.
    fn start(test: &str) -> Option<(std::sync::MutexGuard<'static, ()>, Xvfb)> {
        // One window at a time: with two software-driven windows on two virtual servers at
        // once, one of the two screens grabbed black (lavapipe's presentation, or the grab).
        static ONE: Mutex<()> = Mutex::new(());
        let guard = ONE.lock().unwrap_or_else(|e| e.into_inner());
        if !(have("Xvfb") && have("xdotool") && have("ffmpeg")) {
            assert!(
                std::env::var("CI").is_err(),
                "{test}: Xvfb, xdotool and ffmpeg are needed under CI (scripts/test.sh installs them)"
            );
            eprintln!("{test}: not run (no Xvfb, xdotool or ffmpeg: scripts/test.sh installs them)");
            return None;
        }
        let base = 200 + (std::process::id() % 400) * 8 + test.len() as u32 % 8;
        let free = (base..base + 64).find(|n| {
            !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && !Path::new(&format!("/tmp/.X{n}-lock")).exists()
        });
        let Some(n) = free else {
            // No display number free: not run here, but never a silent pass under CI.
            assert!(std::env::var("CI").is_err(), "{test}: no free X display number in {base}–{} under CI", base + 63);
            eprintln!("{test}: not run (no free X display number in {base}–{})", base + 63);
            return None;
        };
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([&display, "-screen", "0", "640x480x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let socket = format!("/tmp/.X11-unix/X{n}");
        let start = Instant::now();
        while !Path::new(&socket).exists() {
            assert!(start.elapsed() < Duration::from_secs(20), "Xvfb {display} did not start");
            std::thread::sleep(Duration::from_millis(50));
        }
        Some((guard, Xvfb { child, display }))
    }

    /// The screen's top-left `w` × `h` pixels (RGB), grabbed by ffmpeg.
    fn grab(&self, dir: &Path, w: u32, h: u32) -> image::RgbImage {
        let shot = dir.join("shot.png");
        let o = Command::new("ffmpeg")
            .args(["-loglevel", "error", "-y", "-f", "x11grab", "-draw_mouse", "0", "-video_size", "640x480", "-i"])
            .arg(&self.display)
            .args(["-frames:v", "1"])
            .arg(&shot)
            .output()
            .unwrap();
        assert!(o.status.success(), "ffmpeg: {}", String::from_utf8_lossy(&o.stderr));
        image::imageops::crop_imm(&image::open(&shot).unwrap().to_rgb8(), 0, 0, w, h).to_image()
    }

    /// The window's X id (the first window named "twister view").
    fn window_id(&self) -> String {
        let o = Command::new("xdotool")
            .env("DISPLAY", &self.display)
            .args(["search", "--name", "twister view"])
            .output()
            .unwrap();
        String::from_utf8(o.stdout).unwrap().lines().next().expect("a twister view window").to_string()
    }

    fn xdotool(&self, args: &[&str]) {
        let o = Command::new("xdotool").env("DISPLAY", &self.display).args(args).output().unwrap();
        assert!(o.status.success(), "xdotool {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        self.child.kill().ok();
        self.child.wait().ok();
    }
}

/// A running `twister view` and the lines it has written (`--trace-frames`, and stderr).
struct Window {
    child: Child,
    /// The window's standard input (`--head-input -`).
    stdin: Option<std::process::ChildStdin>,
    lines: Arc<Mutex<Vec<String>>>,
    errors: Arc<Mutex<Vec<String>>>,
}

impl Window {
    fn open(x: &Xvfb, args: &[&str]) -> Window {
        Window::open_with(x, args, &[])
    }

    fn open_with(x: &Xvfb, args: &[&str], envs: &[(&str, &str)]) -> Window {
        let mut child = twister()
            .envs(envs.iter().copied())
            .args(["view", "--overlay", "off", "--trace-frames"])
            .args(SIZE)
            .args(args)
            .env("DISPLAY", &x.display)
            .env_remove("WAYLAND_DISPLAY")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let collect = |r: Box<dyn std::io::Read + Send>| {
            let lines = Arc::new(Mutex::new(Vec::new()));
            let sink = lines.clone();
            std::thread::spawn(move || {
                for line in std::io::BufReader::new(r).lines().map_while(|l| l.ok()) {
                    sink.lock().unwrap().push(line);
                }
            });
            lines
        };
        let lines = collect(Box::new(child.stdout.take().unwrap()));
        let errors = collect(Box::new(child.stderr.take().unwrap()));
        let stdin = child.stdin.take();
        Window { child, stdin, lines, errors }
    }

    /// The last frame line once one satisfies `f` (and two more frames were shown after it).
    fn wait_for(&self, what: &str, f: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            {
                let lines = self.lines.lock().unwrap();
                let frames: Vec<&String> = lines.iter().filter(|l| l.starts_with("frame ")).collect();
                if let Some(k) = frames.iter().position(|l| f(l)) {
                    if frames.len() >= k + 3 && frames[k..].iter().all(|l| f(l)) {
                        return frames.last().unwrap().to_string();
                    }
                }
            }
            assert!(
                start.elapsed() < Duration::from_secs(90),
                "waited for {what}: {:?}\nstderr: {:?}",
                self.lines.lock().unwrap().iter().rev().take(3).collect::<Vec<_>>(),
                self.errors.lock().unwrap()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The last frame line once `name`'s value has stayed the same for 0.6 s (and frames went on).
    fn wait_stable(&self, name: &str) -> String {
        let start = Instant::now();
        loop {
            let before = self.wait_for("a frame", |_| true);
            std::thread::sleep(Duration::from_millis(600));
            let after = self.wait_for("a frame", |_| true);
            if field(&before, name) == field(&after, name) && before.split(' ').nth(1) != after.split(' ').nth(1) {
                return after;
            }
            assert!(start.elapsed() < Duration::from_secs(90), "{name} did not settle: {after}");
        }
    }

    fn wait_stderr(&self, f: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            if let Some(l) = self.errors.lock().unwrap().iter().find(|l| f(l)) {
                return l.clone();
            }
            assert!(start.elapsed() < Duration::from_secs(90), "stderr: {:?}", self.errors.lock().unwrap());
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn exit_code(&mut self) -> i32 {
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status.code().unwrap_or(-1);
            }
            assert!(start.elapsed() < Duration::from_secs(60), "the window did not close");
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Window {
    fn drop(&mut self) {
        self.child.kill().ok();
        self.child.wait().ok();
    }
}

/// A field of a frame line (`viewer=…`).
fn field(line: &str, name: &str) -> String {
    let key = format!("{name}=");
    line.split(' ').find_map(|w| w.strip_prefix(&key)).unwrap_or_else(|| panic!("no {name} in {line}")).to_string()
}

/// `render`'s two eyes for the same options, stacked as the window shows them (left on top).
fn rendered(dir: &Path, args: &[&str]) -> (image::RgbImage, PathBuf) {
    let out = dir.join(format!("render-{}", args.join("_").replace(['/', ','], "-")));
    // Another panorama: the width alone (its own aspect, as the window's P key keeps it).
    let size = if args.contains(&"--panorama") { &SIZE[..2] } else { &SIZE[..] };
    let o =
        twister().arg("render").args(size).args(args).args(["--layout", "eyes", "--out"]).arg(&out).output().unwrap();
    assert!(o.status.success(), "render {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    let eye = |e: &str| image::open(out.join(format!("{e}.png"))).unwrap().to_rgb8();
    let (left, right) = (eye("left"), eye("right"));
    let mut both = image::RgbImage::new(left.width(), 2 * left.height());
    image::imageops::replace(&mut both, &left, 0, 0);
    image::imageops::replace(&mut both, &right, 0, left.height() as i64);
    (both, out)
}

fn assert_same(shown: &image::RgbImage, want: &image::RgbImage, what: &str) {
    let differ = shown.pixels().zip(want.pixels()).filter(|(a, b)| a != b).count();
    if differ > 0 {
        let keep = std::env::temp_dir().join(format!("twister-view-failed-{}.png", what.replace(' ', "_")));
        shown.save(&keep).ok();
        eprintln!("the window's pixels: {}", keep.display());
    }
    assert_eq!(differ, 0, "{what}: {differ} of {} pixels differ from render's", want.len() / 3);
}

#[test]
fn the_window_shows_what_render_draws_moves_with_the_keys_and_saves_render_s_files() {
    let Some((_one, x)) = Xvfb::start("keys") else { return };
    let dir = tmp("keys");
    let saved = dir.join("saved");
    let mut w = Window::open(&x, &["--out", saved.to_str().unwrap()]);
    w.wait_for("the first frames", |_| true);
    let (first, _) = rendered(&dir, &[]);
    assert_same(&x.grab(&dir, 128, 64), &first, "the first frame");
    // Hold W: the viewer walks forward (−z) and stops where the key is let go.
    let id = x.window_id();
    x.xdotool(&["windowfocus", "--sync", &id]);
    x.xdotool(&["keydown", "w"]);
    std::thread::sleep(Duration::from_millis(400));
    x.xdotool(&["keyup", "w"]);
    std::thread::sleep(Duration::from_millis(300));
    w.wait_for("the viewer moved", |l| field(l, "viewer") != "0,0,0");
    let moved = w.wait_stable("viewer");
    let viewer = field(&moved, "viewer");
    let z: f32 = viewer.split(',').nth(2).unwrap().parse().unwrap();
    assert!(z < -0.1 && viewer.starts_with("0,0,"), "W walks forward: {viewer}");
    let (want, render_out) = rendered(&dir, &["--viewer", &viewer]);
    assert_same(&x.grab(&dir, 128, 64), &want, &format!("after W ({moved})"));
    // F12: render's files for the window's settings, byte for byte.
    x.xdotool(&["key", "F12"]);
    w.wait_stderr(|l| l.starts_with("saved into"));
    for eye in ["left.png", "right.png"] {
        let (a, b) = (std::fs::read(saved.join(eye)).unwrap(), std::fs::read(render_out.join(eye)).unwrap());
        assert!(a == b, "{eye}: the saved file is not render's");
    }
    // M: the next method (vertex), drawn as render draws it.
    x.xdotool(&["key", "m"]);
    w.wait_for("vertex", |l| field(l, "method") == "vertex");
    let (vertex, _) = rendered(&dir, &["--viewer", &viewer, "--method", "vertex"]);
    assert_same(&x.grab(&dir, 128, 64), &vertex, "vertex");
    assert!(vertex != want, "the methods differ on this frame");
    // N: 8 samples (beyond lavapipe's 4: a larger image box-filtered, then shown).
    x.xdotool(&["key", "n"]);
    w.wait_for("8 samples", |l| field(l, "samples") == "8");
    let (eight, _) = rendered(&dir, &["--viewer", &viewer, "--method", "vertex", "--samples", "8"]);
    assert_same(&x.grab(&dir, 128, 64), &eight, "8 samples");
    // P: the full sphere at the width asked for (128 × 64 per eye), fitted into the window.
    x.xdotool(&["key", "p"]);
    w.wait_for("the sphere", |l| field(l, "panorama") == "Equirect");
    let sphere_args = ["--viewer", viewer.as_str(), "--method", "vertex", "--samples", "8", "--panorama", "equirect"];
    let (sphere, _) = rendered(&dir, &sphere_args);
    let projection = Projection { height: 64, ..Projection::equirect(128) };
    assert_close(
        &x.grab(&dir, 128, 64),
        &displayed(&sphere, 2, DisplayMode::Panorama, Look::default(), [128, 64], projection),
        "the sphere",
    );
    x.xdotool(&["key", "Escape"]);
    assert_eq!(w.exit_code(), 0, "Escape closes the window: {:?}", w.errors.lock().unwrap());
}

/// The display twin (`cpu::display`) of an image of `layers` stacked layers (render's eyes: 2;
/// a heatmap: 1): what the window must show in `mode`.
fn displayed(
    img: &image::RgbImage,
    layers: u32,
    mode: DisplayMode,
    look: Look,
    target: [u32; 2],
    projection: Projection,
) -> image::RgbImage {
    let texels: Vec<u32> =
        img.pixels().map(|p| p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16 | 0xff << 24).collect();
    let size = [img.width(), img.height() / layers];
    let view =
        DisplayView { mode, look, image: size, layers, row_texels: size[0], target, overlay: None, srgb_target: false };
    let words =
        display(&twister::encoding::params::display_params(&view, &projection), &projection, &texels, &[], target);
    image::RgbImage::from_fn(target[0], target[1], |x, y| {
        let w = words[(y * target[0] + x) as usize];
        image::Rgb([w as u8, (w >> 8) as u8, (w >> 16) as u8])
    })
}

/// At most 0.5 % of the pixels differ (a window pixel on a texel's edge may take its neighbour:
/// the GPU's arithmetic and the twin's).
fn assert_close(shown: &image::RgbImage, want: &image::RgbImage, what: &str) {
    let differ = shown.pixels().zip(want.pixels()).filter(|(a, b)| a != b).count();
    let uniform = want.pixels().all(|p| p == want.get_pixel(0, 0));
    assert!(!uniform, "{what}: the expected image is one colour");
    if differ * 200 > want.len() / 3 {
        let keep = std::env::temp_dir().join(format!("twister-view-failed-{}.png", what.replace(' ', "_")));
        shown.save(&keep).ok();
        want.save(keep.with_extension("want.png")).ok();
        panic!(
            "{what}: {differ} of {} pixels differ from the display twin's (the window's: {})",
            want.len() / 3,
            keep.display()
        );
    }
}

#[test]
fn every_display_shows_render_s_frame_through_the_display_twin_after_a_resize_and_a_drag() {
    let Some((_one, x)) = Xvfb::start("displays") else { return };
    let dir = tmp("displays");
    let mut w = Window::open(&x, &[]);
    w.wait_for("the first frames", |_| true);
    let (eyes, _) = rendered(&dir, &[]);
    let id = x.window_id();
    // A resize: the panoramas fitted into the new size.
    x.xdotool(&["windowsize", "--sync", &id, "300", "200"]);
    std::thread::sleep(Duration::from_millis(500));
    w.wait_for("frames after the resize", |_| true);
    let target = [300, 200];
    assert_close(
        &x.grab(&dir, 300, 200),
        &displayed(&eyes, 2, DisplayMode::Panorama, Look::default(), target, cylinder()),
        "resized",
    );
    x.xdotool(&["windowfocus", "--sync", &id]);
    for (mode, show) in [(DisplayMode::Halves, "display halves"), (DisplayMode::LookSideBySide, "look-around")] {
        x.xdotool(&["key", "v"]);
        w.wait_for(show, |l| l.contains(&format!("show={show} ")));
        assert_close(&x.grab(&dir, 300, 200), &displayed(&eyes, 2, mode, Look::default(), target, cylinder()), show);
    }
    // A drag turns the gaze: right and up.
    x.xdotool(&["mousemove", "--window", &id, "100", "120", "mousedown", "1"]);
    x.xdotool(&["mousemove", "--window", &id, "140", "100"]);
    x.xdotool(&["mouseup", "1"]);
    w.wait_for("the drag", |l| !l.contains(" look=0,0 "));
    let line = w.wait_stable("look");
    let look: Vec<f32> = field(&line, "look").split(',').map(|v| v.parse().unwrap()).collect();
    assert!(look[0] > 0.05 && look[1] > 0.05, "dragged right and up: {look:?}");
    let look = Look { yaw: look[0], pitch: look[1], ..Look::default() };
    assert_close(
        &x.grab(&dir, 300, 200),
        &displayed(&eyes, 2, DisplayMode::LookSideBySide, look, target, cylinder()),
        "dragged",
    );
    x.xdotool(&["key", "v"]);
    w.wait_for("anaglyph", |l| l.contains("show=anaglyph "));
    assert_close(
        &x.grab(&dir, 300, 200),
        &displayed(&eyes, 2, DisplayMode::LookAnaglyph, look, target, cylinder()),
        "anaglyph",
    );
    // The error heatmap: `error --heatmap`'s image, fitted.
    x.xdotool(&["key", "v"]);
    w.wait_for("the heatmap", |l| l.contains("show=error heatmap "));
    let heatmap = dir.join("heatmap.png");
    let o = twister().arg("error").args(SIZE).arg("--heatmap").arg(&heatmap).output().unwrap();
    assert!(o.status.success(), "error: {}", String::from_utf8_lossy(&o.stderr));
    let map = image::open(&heatmap).unwrap().to_rgb8();
    let want = displayed(&map, 1, DisplayMode::Panorama, look, target, cylinder());
    assert_close(&x.grab(&dir, 300, 200), &want, "heatmap");
    // The window closed (destroyed: there is no window manager to ask it): exit 0.
    x.xdotool(&["windowclose", &id]);
    assert_eq!(w.exit_code(), 0, "{:?}", w.errors.lock().unwrap());
}

#[test]
fn head_input_lines_move_the_head_and_a_bad_line_stops_the_window() {
    let Some((_one, x)) = Xvfb::start("head-input") else { return };
    let dir = tmp("head");
    let input = dir.join("head.csv");
    std::fs::create_dir_all(&*dir).unwrap();
    // Good lines only: the window goes on with them (its first frame may take seconds on a busy
    // machine, so a bad line in the same file could close it before the screen is grabbed).
    std::fs::write(&input, "0,0.2,0,-0.1,15,0\n8,0.2,0,-0.1,15,0\n").unwrap();
    let w = Window::open(&x, &["--head-input", input.to_str().unwrap()]);
    let line = w.wait_for("the head", |l| l.contains(" head="));
    assert_eq!(field(&line, "head"), "0.2,0,-0.1,15");
    let grabbed = x.grab(&dir, 128, 64);
    drop(w); // killed and waited for
    let (want, _) = rendered(&dir, &["--head", "0.2,0,-0.1,15"]);
    assert_same(&grabbed, &want, "the head input's head");
    let (still, _) = rendered(&dir, &[]);
    assert!(want != still, "the head moved the frame");
    // Line 3 is not six numbers: one line naming it, exit non-zero.
    std::fs::write(&input, "0,0.2,0,-0.1,15,0\n1,0.2,0,-0.1,15,0\n2,oops\n").unwrap();
    let mut w = Window::open(&x, &["--head-input", input.to_str().unwrap()]);
    let error = w.wait_stderr(|l| l.starts_with("error:"));
    assert!(error.contains("head.csv line 3"), "{error}");
    assert_ne!(w.exit_code(), 0);
    // A monitor the window system lacks: one line, before any window.
    let o = twister().args(["view", "--monitor", "5"]).args(SIZE).env("DISPLAY", &x.display).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.lines().count() == 1 && err.contains("--monitor") && err.contains("has 1 monitor,"),
        "{err}"
    );
}

#[test]
fn space_plays_the_animation_and_f12_saves_the_posed_frame_as_render_frames_does() {
    if !common::assets_present() {
        return;
    }
    let Some((_one, x)) = Xvfb::start("animation") else { return };
    let dir = tmp("animation");
    let scene = common::asset("gltf/CesiumMan/glTF-Binary/CesiumMan.glb");
    let scene = scene.to_str().unwrap();
    let saved = dir.join("saved");
    let mut w = Window::open(&x, &[scene, "--fit", "2", "--method", "vertex", "--out", saved.to_str().unwrap()]);
    w.wait_for("the first frames", |_| true);
    let id = x.window_id();
    x.xdotool(&["windowfocus", "--sync", &id]);
    x.xdotool(&["key", "space"]);
    w.wait_for("the animation to play", |l| field(l, "anim_frame") != "0");
    x.xdotool(&["key", "space"]);
    // Paused: the same posed frame from then on.
    let start = Instant::now();
    let frame = loop {
        let last = w.wait_for("a frame", |_| true);
        let k = field(&last, "anim_frame");
        std::thread::sleep(Duration::from_millis(600));
        if field(&w.wait_for("a frame", |_| true), "anim_frame") == k {
            break k;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "the animation did not pause");
    };
    assert_ne!(frame, "0");
    let out = dir.join("render");
    let o = twister()
        .args(["render", scene, "--fit", "2", "--method", "vertex", "--layout", "eyes", "--frames", &frame, "--out"])
        .arg(&out)
        .args(SIZE)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let k: u32 = frame.parse().unwrap();
    let eye = |e: &str| image::open(out.join(format!("frame_{k:06}_{e}.png"))).unwrap().to_rgb8();
    let mut both = image::RgbImage::new(128, 64);
    image::imageops::replace(&mut both, &eye("left"), 0, 0);
    image::imageops::replace(&mut both, &eye("right"), 0, 32);
    assert_same(&x.grab(&dir, 128, 64), &both, &format!("posed frame {k}"));
    x.xdotool(&["key", "F12"]);
    w.wait_stderr(|l| l.starts_with("saved into"));
    for e in ["left", "right"] {
        let name = format!("frame_{k:06}_{e}.png");
        assert!(std::fs::read(saved.join(&name)).unwrap() == std::fs::read(out.join(&name)).unwrap(), "{name}");
    }
    x.xdotool(&["key", "Escape"]);
    assert_eq!(w.exit_code(), 0);
}

#[test]
fn with_visual_field_lod_the_detail_follows_the_dragged_gaze_as_render_gaze_draws_it() {
    let Some((_one, x)) = Xvfb::start("lod-gaze") else { return };
    let dir = tmp("lod");
    let mut w = Window::open(&x, &["--lod", "visual-field"]);
    let first = w.wait_for("the first frames", |_| true);
    let id = x.window_id();
    // Five drags across the window: about half a turn to the right and down.
    for _ in 0..5 {
        x.xdotool(&["mousemove", "--window", &id, "10", "20", "mousedown", "1"]);
        x.xdotool(&["mousemove", "--window", &id, "120", "40"]);
        x.xdotool(&["mouseup", "1"]);
    }
    w.wait_for("the gaze turned", |l| field(l, "gaze") != field(&first, "gaze"));
    let line = w.wait_stable("gaze");
    let gaze = field(&line, "gaze");
    assert_ne!(field(&line, "triangles"), field(&first, "triangles"), "the selection follows the gaze");
    let (want, _) = rendered(&dir, &["--lod", "visual-field", "--gaze", &gaze]);
    assert_same(&x.grab(&dir, 128, 64), &want, &format!("gaze {gaze}"));
    x.xdotool(&["windowfocus", "--sync", &id]);
    x.xdotool(&["key", "Escape"]);
    assert_eq!(w.exit_code(), 0);
}

#[test]
fn the_display_halves_fill_the_monitor_named() {
    let Some((_one, x)) = Xvfb::start("monitor") else { return };
    let dir = tmp("monitor");
    let w = Window::open(&x, &["--monitor", "0", "--show", "halves"]);
    w.wait_for("the first frames", |_| true);
    std::thread::sleep(Duration::from_millis(300));
    let (eyes, _) = rendered(&dir, &[]);
    let whole = displayed(&eyes, 2, DisplayMode::Halves, Look::default(), [640, 480], cylinder());
    assert_close(&x.grab(&dir, 640, 480), &whole, "halves on monitor 0");
    drop(w); // killed and waited for
}

#[test]
fn head_input_from_standard_input_moves_the_head_as_lines_arrive() {
    use std::io::Write;
    let Some((_one, x)) = Xvfb::start("stdin") else { return };
    let dir = tmp("stdin");
    let mut w = Window::open(&x, &["--head-input", "-"]);
    let first = w.wait_for("the first frames", |_| true);
    assert!(!first.contains(" head="), "no head before a line: {first}");
    let mut stdin = w.stdin.take().unwrap();
    writeln!(stdin, "0,-0.1,0.05,0.2,-20,0").unwrap();
    stdin.flush().unwrap();
    let line = w.wait_for("the piped head", |l| l.contains(" head="));
    assert_eq!(field(&line, "head"), "-0.1,0.05,0.2,-20");
    let (want, _) = rendered(&dir, &["--head", "-0.1,0.05,0.2,-20"]);
    assert_same(&x.grab(&dir, 128, 64), &want, "the piped head");
    // The tracker ends: the window goes on with the last head.
    drop(stdin);
    std::thread::sleep(Duration::from_millis(300));
    w.wait_for("frames after the input ended", |l| l.contains(" head=-0.1,0.05,0.2,-20 "));
    assert!(w.child.try_wait().unwrap().is_none(), "the window closed when its input ended");
    drop(w); // killed and waited for
}

#[test]
fn a_lost_device_is_opened_again_and_the_window_goes_on_as_it_was() {
    let Some((_one, x)) = Xvfb::start("lost-device") else { return };
    let dir = tmp("lost");
    let mut w = Window::open_with(&x, &[], &[("TWISTER_VIEW_TEST_KEYS", "1")]);
    w.wait_for("the first frames", |_| true);
    let id = x.window_id();
    x.xdotool(&["windowfocus", "--sync", &id]);
    x.xdotool(&["key", "v"]);
    w.wait_for("the halves", |l| l.contains("show=display halves "));
    // F9 (the test hook) destroys the device.
    x.xdotool(&["key", "F9"]);
    let warning = w.wait_stderr(|l| l.contains("device was lost"));
    assert!(warning.starts_with("warning:"), "{warning}");
    let lost_at = w.lines.lock().unwrap().len();
    let start = Instant::now();
    while w.lines.lock().unwrap().len() < lost_at + 5 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no frames after the device was lost: {:?}",
            w.errors.lock().unwrap()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    w.wait_for("the halves again", |l| l.contains("show=display halves "));
    let (eyes, _) = rendered(&dir, &[]);
    assert_close(
        &x.grab(&dir, 128, 64),
        &displayed(&eyes, 2, DisplayMode::Halves, Look::default(), [128, 64], cylinder()),
        "after the loss",
    );
    x.xdotool(&["windowfocus", "--sync", &id]);
    x.xdotool(&["key", "Escape"]);
    assert_eq!(w.exit_code(), 0, "{:?}", w.errors.lock().unwrap());
}

#[test]
fn view_refuses_bad_options_and_a_missing_window_system_in_one_line() {
    let dir = tmp("bad");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--frames".into(), "1..2".into()], "--frames"),
        (vec!["--speed".into(), "0".into()], "--speed"),
        (vec!["--head-input".into(), dir.join("missing.csv").display().to_string()], "missing.csv"),
        (vec!["--panorama".into(), "cave".into()], "--cave"),
        (vec![], "DISPLAY and WAYLAND_DISPLAY are unset"),
    ];
    for (args, says) in cases {
        let o = twister()
            .arg("view")
            .args(SIZE)
            .args(&args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert_eq!(err.lines().count(), 1, "{args:?}: one line: {err}");
        assert!(err.contains(says) && !err.contains("panicked"), "{args:?}: {err}");
    }
}
