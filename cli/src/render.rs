//! `twister render` of one still: both eyes' panoramas of a scene, written by the frame writer
//! as a layout of images (and depth, linear colour, statistics where asked), all or nothing.

use crate::args::{LodMode, RenderArgs};
use crate::scene::{lod_stats, open_renderer, prepare};
use crate::writer::{FrameRecord, FrameWriter};
use twister::error::{Error, Result};
use twister::output::{check_outputs, write_all, OutputFile};

/// `render`'s samples per pixel where `--samples` is not given (WebGPU guarantees 4 on every
/// adapter).
pub const DEFAULT_SAMPLES: u32 = 4;

/// The render settings `args` ask for, with the outputs' measures (depth, edge lengths for the
/// statistics, the linear colour) and the background, checked as a whole; then only read.
pub fn render_settings(args: &RenderArgs) -> Result<twister::RenderSettings> {
    // A CAVE sequence's head path: the base settings see the head where it starts.
    let view = match crate::cave::cave_head_start(args)? {
        Some(head) => &crate::args::ViewArgs { head: Some(head), ..args.view.clone() },
        None => &args.view,
    };
    let settings = view
        .settings(&[args.view.method])?
        .with_background(args.background)
        .with_measure_edges(args.stats.is_some())
        .with_depth(args.depth)
        .with_hdr(args.hdr);
    // Four samples unless asked otherwise (the ray tracer: four rays per pixel), textures
    // filtered with the most anisotropy.
    let settings = settings
        .with_samples(args.view.samples.unwrap_or(DEFAULT_SAMPLES))
        .with_anisotropy(args.view.anisotropy.unwrap_or(twister::core::settings::MAX_ANISOTROPY));
    settings.validate()?;
    Ok(settings)
}

/// What a still draws: its settings, checked, and each view's projection (a CAVE's walls; one
/// view otherwise) with the writer of its files.
pub struct Still {
    pub settings: twister::RenderSettings,
    pub views: Vec<(Option<twister::Projection>, FrameWriter)>,
}

/// The still that `args` ask for, every option checked before anything is drawn.
pub fn still(args: &RenderArgs) -> Result<Still> {
    for (given, option) in [
        (args.resume, "--resume"),
        (args.shard.is_some(), "--shard"),
        (args.animation.is_some(), "--animation"),
        (args.video.is_some(), "--video"),
        (args.gaze_path.is_some(), "--gaze-path"),
        (args.viewer_path.is_some(), "--viewer-path"),
        (args.head_path.is_some(), "--head-path"),
    ] {
        if given {
            return Err(Error::option(option, "belongs to a sequence: use it with --frames A..B"));
        }
    }
    if let Some(side) = args.max_tile.filter(|&s| s < 16) {
        return Err(Error::option("--max-tile", format!("must be at least 16 pixels, got {side}")));
    }
    let settings = render_settings(args)?;
    let writer = FrameWriter::new(args, &settings, false)?;
    if args.lod_overlay && args.view.lod == LodMode::Off {
        return Err(Error::option("--lod-overlay", "needs --lod visual-field"));
    }
    // One view, or a CAVE's walls: each its projection and its writer (files named by wall).
    let walls = args.view.cave_walls(&settings)?;
    let views = if walls.is_empty() {
        vec![(None, writer)]
    } else {
        walls.into_iter().map(|(name, p)| (Some(p), writer.for_wall(Some(name)))).collect()
    };
    Ok(Still { settings, views })
}

impl Still {
    /// Each view's settings placed with the scene (`placed`: the settings `prepare` returned; a
    /// CAVE's walls each on its wall), with its writer.
    pub fn placed(self, placed: twister::RenderSettings) -> Vec<(twister::RenderSettings, FrameWriter)> {
        self.views
            .into_iter()
            .map(|(wall, writer)| match wall {
                Some(wall) => (crate::cave::on_wall(placed, &wall), writer),
                None => (placed, writer),
            })
            .collect()
    }
}

/// One view of a still, drawn: its settings (placed with the scene, on its wall), the frame, its
/// writer and, with `--stats`, its record.
pub struct Drawn {
    pub settings: twister::RenderSettings,
    pub frame: twister::Frame,
    pub writer: FrameWriter,
    pub record: Option<serde_json::Value>,
}

/// Draws each placed view ([`Still::placed`]) from the prepared scene (the frame writer's
/// record when `stats`).
pub fn draw(
    renderer: &twister::Renderer,
    adapter: &str,
    args: &RenderArgs,
    prepared: &crate::scene::Prepared,
    views: Vec<(twister::RenderSettings, FrameWriter)>,
    stats: bool,
) -> Result<Vec<Drawn>> {
    let mut drawn = Vec::new();
    for (settings, writer) in views {
        let mut frame = renderer.render(&prepared.gpu_scene, &settings)?;
        if let (true, Some(gaze)) = (args.lod_overlay, &prepared.gaze) {
            for img in [&mut frame.left, &mut frame.right] {
                twister::core::detail::lod::draw_field_boundaries(img, settings.projection(), gaze);
            }
        }
        let record = stats.then(|| {
            let record =
                FrameRecord::new(&args.scene, &settings, &frame, &writer, adapter, lod_stats(&prepared.selection));
            serde_json::to_value(&record).expect("JSON of plain values")
        });
        drawn.push(Drawn { settings, frame, writer, record });
    }
    Ok(drawn)
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let still = still(args)?;
    // Every output is checked before anything is rendered, and all are written together.
    let image_paths: Vec<std::path::PathBuf> = still.views.iter().flat_map(|(_, w)| w.paths(None)).collect();
    let mut all_paths: Vec<&std::path::Path> = image_paths.iter().map(|p| p.as_path()).collect();
    all_paths.extend(args.stats.as_deref());
    check_outputs(&all_paths)?;
    let (renderer, adapter) = open_renderer()?;
    let method = [still.settings.subdivision.method];
    let prepared = prepare(&renderer, &args.scene, args.fit, &args.view, still.settings, args.lod_overlay, &method)?;
    let views = still.placed(prepared.settings);
    // Larger than the adapter draws at once (or --max-tile): in tiles, streamed (`tiled`).
    let all: Vec<twister::RenderSettings> = views.iter().map(|(s, _)| *s).collect();
    if crate::tiled::any_tiled(&renderer, &all, args.max_tile) {
        for path in crate::tiled::render_streamed(args, &renderer, &prepared, &views, &adapter)? {
            println!("{}", path.display());
        }
        return Ok(());
    }
    let mut files = Vec::new();
    let mut records = Vec::new();
    for drawn in draw(&renderer, &adapter, args, &prepared, views, args.stats.is_some())? {
        let t = std::time::Instant::now();
        files.extend(drawn.writer.files(&drawn.frame, None)?);
        // Encoding: the writing itself is a rename.
        let ms_write = t.elapsed().as_secs_f64() * 1e3;
        if let Some(mut record) = drawn.record {
            record["ms_write"] = ms_write.into();
            record["ms_total"] = (drawn.frame.stats.ms_total + ms_write).into();
            records.push(record);
        }
    }
    let written = files.len();
    if let Some(path) = &args.stats {
        // One object; a CAVE's walls: one per wall, in an array.
        let value = if records.len() == 1 { records.remove(0) } else { serde_json::Value::Array(records) };
        let text = serde_json::to_string_pretty(&value).expect("JSON of plain values");
        files.push(OutputFile { path: path.clone(), bytes: text.into_bytes() });
    }
    write_all(&files)?;
    for f in files.iter().take(written) {
        if image_paths.contains(&f.path) {
            println!("{}", f.path.display());
        }
    }
    Ok(())
}
