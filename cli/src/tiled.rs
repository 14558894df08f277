//! A still larger than the adapter draws at once (`Renderer::tiles`: beyond its textures or its
//! read-back buffer, or `--max-tile`): each view is drawn strip by strip into a spool file
//! beside the outputs (both eyes' RGBA rows), then every layout image is encoded from the spool
//! row by row (`output::stream_image`, PNG or JPEG): memory holds a strip and a few rows, never
//! the frame; the files are put in place together, as every still's.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use twister::error::{Error, Result};
use twister::gpu::renderer::Tiles;
use twister::{Projection, RenderSettings, Renderer};

use crate::args::RenderArgs;
use crate::scene::{lod_stats, Prepared};
use crate::writer::{FrameRecord, FrameWriter};

/// A frame on disk: both eyes' colour (RGBA8), then their depth (f32) and linear colour (3 ×
/// f32) where drawn, each eye-major rows.
struct Spool {
    path: PathBuf,
    file: File,
    size: [u32; 2],
}

/// The spool's parts: bytes per pixel, and where each begins (in bytes per pixel of one eye).
const COLOUR: (u64, u64) = (4, 0);
const DEPTH: (u64, u64) = (4, 8);
const HDR: (u64, u64) = (12, 16);

impl Spool {
    fn create(dir: &Path, view: usize, size: [u32; 2]) -> Result<Spool> {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::output(dir, format!("cannot create the output folder: {e}")))?;
        let path = dir.join(format!(".twister-spool-{view}.{}.tmp", std::process::id()));
        let file = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(&path)
            .map_err(|e| Error::output(&path, format!("cannot write the tiles' spool: {e}")))?;
        Ok(Spool { path, file, size })
    }

    /// Writes a strip of the frame (both eyes' colour, depth, linear colour) starting at row `y`.
    fn write_strip(&mut self, y: u32, strip: &twister::Frame) -> Result<()> {
        let [w, h] = self.size.map(|v| v as u64);
        let (file, path) = (&mut self.file, &self.path);
        let mut put = |(bytes, base): (u64, u64), eye: u64, data: &[u8]| {
            let at = base * w * h + bytes * ((eye * h + y as u64) * w);
            let fail = |e: std::io::Error| Error::output(path, format!("cannot write the tiles' spool: {e}"));
            file.seek(SeekFrom::Start(at)).map_err(fail)?;
            file.write_all(data).map_err(fail)
        };
        for (eye, img) in [&strip.left, &strip.right].into_iter().enumerate() {
            put(COLOUR, eye as u64, &img.rgba)?;
        }
        if let Some(depth) = &strip.depth {
            for (eye, values) in depth.iter().enumerate() {
                put(DEPTH, eye as u64, bytemuck::cast_slice(values))?;
            }
        }
        if let Some(hdr) = &strip.hdr {
            for (eye, values) in hdr.iter().enumerate() {
                put(HDR, eye as u64, bytemuck::cast_slice(values))?;
            }
        }
        Ok(())
    }
}

/// A reader of a spool's rows (each file encoded opens its own).
struct SpoolReader {
    file: File,
    path: PathBuf,
    size: [u32; 2],
}

impl SpoolReader {
    fn open(spool: &Spool) -> Result<SpoolReader> {
        let file =
            File::open(&spool.path).map_err(|e| Error::output(&spool.path, format!("cannot read the spool: {e}")))?;
        Ok(SpoolReader { file, path: spool.path.clone(), size: spool.size })
    }

    /// Columns [x, x + n) of row `row` of eye `eye` of a part of the spool, as bytes.
    fn read(&mut self, (bytes, base): (u64, u64), eye: usize, row: u32, x: u32, n: u32) -> Result<Vec<u8>> {
        let [w, h] = self.size.map(|v| v as u64);
        let at = base * w * h + bytes * ((eye as u64 * h + row as u64) * w + x as u64);
        let mut out = vec![0; (bytes * n as u64) as usize];
        let fail = |e: std::io::Error| Error::output(&self.path, format!("cannot read the spool: {e}"));
        self.file.seek(SeekFrom::Start(at)).map_err(fail)?;
        self.file.read_exact(&mut out).map_err(fail)?;
        Ok(out)
    }

    /// The same as floats (depth, linear colour).
    fn floats(&mut self, part: (u64, u64), eye: usize, row: u32, x: u32, n: u32) -> Result<Vec<f32>> {
        let bytes = self.read(part, eye, row, x, n)?;
        Ok(bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
    }
}

impl Drop for Spool {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A view drawn in tiles: its statistics (summed over the tiles) and its tiles.
pub type Drawn = (twister::FrameStats, Tiles);

/// Whether any view of a still is drawn in tiles.
pub fn any_tiled(renderer: &Renderer, views: &[RenderSettings], max_tile: Option<u32>) -> bool {
    views.iter().any(|s| renderer.tiles(s, max_tile).is_some())
}

/// Draws each view (its settings and writer) in tiles into its spool, then writes every image
/// of every view from the spools (frame `frame` of a sequence: its numbered names), all or
/// nothing, with the file `extra` gives from each view's statistics and tiles (a still's
/// `--stats`); returns the images' paths and each view's statistics.
pub fn stream_views(
    args: &RenderArgs,
    renderer: &Renderer,
    gpu_scene: &twister::GpuScene,
    views: &[(RenderSettings, FrameWriter)],
    frame: Option<u32>,
    extra: impl FnOnce(&[Drawn]) -> Option<(PathBuf, String)>,
) -> Result<(Vec<PathBuf>, Vec<Drawn>)> {
    if args.lod_overlay {
        return Err(Error::option(
            "--lod-overlay",
            "draws on a frame held whole: a frame drawn in tiles (larger than the adapter draws at once, or --max-tile) has none",
        ));
    }
    let mut spools = Vec::with_capacity(views.len());
    let mut drawn = Vec::with_capacity(views.len());
    for (k, (settings, _)) in views.iter().enumerate() {
        let p: &Projection = settings.projection();
        let tiles = renderer.tiles(settings, args.max_tile).unwrap_or(Tiles::whole(p.width, p.height));
        let mut spool = Spool::create(&args.out, k, [p.width, p.height])?;
        let stats = renderer.render_tiled(gpu_scene, settings, tiles, |y, strip| spool.write_strip(y, &strip))?;
        drawn.push((stats, tiles));
        spools.push(spool);
    }
    // Every file of every view (images, then depth and linear colour), streamed from its spool;
    // then the extra file.
    let images: Vec<(usize, usize)> =
        views.iter().enumerate().flat_map(|(v, (_, w))| (0..w.paths(frame).len()).map(move |i| (v, i))).collect();
    let mut paths: Vec<PathBuf> = images.iter().map(|&(v, i)| views[v].1.paths(frame)[i].clone()).collect();
    let written = paths.clone();
    let extra = extra(&drawn);
    if let Some((path, _)) = &extra {
        paths.push(path.clone());
    }
    twister::output::write_all_with(&paths, |k, temp| {
        let Some(&(v, image)) = images.get(k) else {
            let text = extra.as_ref().map_or("", |(_, text)| text.as_str());
            return std::fs::write(temp, text).map_err(|e| Error::output(&paths[k], format!("cannot write: {e}")));
        };
        let (writer, size) = (&views[v].1, spools[v].size);
        let mut reader = SpoolReader::open(&spools[v])?;
        let images = writer.image_names().len();
        let depths = if views[v].0.measure.depth { writer.depth_names().len() } else { 0 };
        if image < images {
            return writer
                .stream_image(image, &paths[k], temp, size, &mut |eye, row, x, n| reader.read(COLOUR, eye, row, x, n));
        }
        if image < images + depths {
            let file = image - images;
            return writer
                .stream_depth(file, &paths[k], temp, size, &mut |eye, row, x, n| reader.floats(DEPTH, eye, row, x, n));
        }
        let eye = image - images - depths;
        twister::output::stream_exr(&paths[k], temp, size, 3, |row| reader.floats(HDR, eye, row, 0, size[0]))
    })?;
    Ok((written, drawn))
}

/// A still's views in tiles ([`stream_views`]), with `--stats` one record per view written with
/// the images; returns the images' paths.
pub fn render_streamed(
    args: &RenderArgs,
    renderer: &Renderer,
    prepared: &Prepared,
    views: &[(RenderSettings, FrameWriter)],
    adapter: &str,
) -> Result<Vec<PathBuf>> {
    let stats_file = |drawn: &[Drawn]| {
        let path = args.stats.clone()?;
        let mut records: Vec<serde_json::Value> = drawn
            .iter()
            .zip(views)
            .map(|((stats, tiles), (settings, writer))| {
                let frame = stats_frame(stats);
                let record = FrameRecord {
                    tiles: Some(tiles.count()),
                    ..FrameRecord::new(&args.scene, settings, &frame, writer, adapter, lod_stats(&prepared.selection))
                };
                serde_json::to_value(&record).expect("JSON of plain values")
            })
            .collect();
        let value = if records.len() == 1 { records.remove(0) } else { serde_json::Value::Array(records) };
        Some((path, serde_json::to_string_pretty(&value).expect("JSON of plain values")))
    };
    Ok(stream_views(args, renderer, &prepared.gpu_scene, views, None, stats_file)?.0)
}

/// A frame holding only statistics (a tiled frame's images are on disk).
pub fn stats_frame(stats: &twister::FrameStats) -> twister::Frame {
    twister::Frame {
        left: Default::default(),
        right: Default::default(),
        stats: stats.clone(),
        measurement: None,
        depth: None,
        positions: None,
        hdr: None,
    }
}
