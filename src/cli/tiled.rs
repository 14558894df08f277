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

/// Both eyes' colour of a frame on disk: eye-major rows of RGBA.
struct Spool {
    path: PathBuf,
    file: File,
    size: [u32; 2],
}

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

    fn offset(&self, eye: usize, row: u32, x: u32) -> u64 {
        let [w, h] = self.size.map(|v| v as u64);
        4 * ((eye as u64 * h + row as u64) * w + x as u64)
    }

    /// Writes a strip of both eyes starting at row `y`.
    fn write_strip(&mut self, y: u32, eyes: &[twister::EyeImage; 2]) -> Result<()> {
        for (eye, img) in eyes.iter().enumerate() {
            let at = self.offset(eye, y, 0);
            let fail = |e: std::io::Error| Error::output(&self.path, format!("cannot write the tiles' spool: {e}"));
            self.file.seek(SeekFrom::Start(at)).map_err(fail)?;
            self.file.write_all(&img.rgba).map_err(fail)?;
        }
        Ok(())
    }
}

/// A reader of a spool's rows (each image encoded opens its own).
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

    /// Columns [x, x + n) of row `row` of eye `eye`, RGBA.
    fn read(&mut self, eye: usize, row: u32, x: u32, n: u32) -> Result<Vec<u8>> {
        let [w, h] = self.size.map(|v| v as u64);
        let at = 4 * ((eye as u64 * h + row as u64) * w + x as u64);
        let mut bytes = vec![0; 4 * n as usize];
        let fail = |e: std::io::Error| Error::output(&self.path, format!("cannot read the spool: {e}"));
        self.file.seek(SeekFrom::Start(at)).map_err(fail)?;
        self.file.read_exact(&mut bytes).map_err(fail)?;
        Ok(bytes)
    }
}

impl Drop for Spool {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Whether any view of a still is drawn in tiles.
pub fn any_tiled(renderer: &Renderer, views: &[RenderSettings], max_tile: Option<u32>) -> bool {
    views.iter().any(|s| renderer.tiles(s, max_tile).is_some())
}

/// Draws each view (its settings and writer) in tiles into its spool, then writes every image
/// of every view from the spools, all or nothing; returns the paths written and, with
/// `--stats`, one record per view.
pub fn render_streamed(
    args: &RenderArgs,
    renderer: &Renderer,
    prepared: &Prepared,
    views: &[(RenderSettings, FrameWriter)],
    adapter: &str,
) -> Result<Vec<PathBuf>> {
    for (given, option) in [(args.depth, "--depth"), (args.hdr, "--hdr"), (args.lod_overlay, "--lod-overlay")] {
        if given {
            return Err(Error::option(
                option,
                "a frame drawn in tiles (larger than the adapter draws at once, or --max-tile) writes its colour only",
            ));
        }
    }
    let mut spools = Vec::with_capacity(views.len());
    let mut records = Vec::new();
    for (k, (settings, writer)) in views.iter().enumerate() {
        let p: &Projection = settings.projection();
        let tiles = renderer.tiles(settings, args.max_tile).unwrap_or(Tiles {
            width: p.width,
            height: p.height,
            tile_w: p.width,
            tile_h: p.height,
        });
        let mut spool = Spool::create(&args.out, k, [p.width, p.height])?;
        let stats =
            renderer.render_tiled(&prepared.gpu_scene, settings, tiles, |y, eyes| spool.write_strip(y, &eyes))?;
        if args.stats.is_some() {
            let frame = twister::Frame {
                left: Default::default(),
                right: Default::default(),
                stats,
                measurement: None,
                depth: None,
                positions: None,
                hdr: None,
            };
            let record = FrameRecord {
                tiles: Some(tiles.count()),
                ..FrameRecord::new(&args.scene, settings, &frame, writer, adapter, lod_stats(&prepared.selection))
            };
            records.push(serde_json::to_value(&record).expect("JSON of plain values"));
        }
        spools.push(spool);
    }
    // Every image of every view, streamed from its spool; then the statistics.
    let images: Vec<(usize, usize)> =
        views.iter().enumerate().flat_map(|(v, (_, w))| (0..w.image_names().len()).map(move |i| (v, i))).collect();
    let mut paths: Vec<PathBuf> = images.iter().map(|&(v, i)| views[v].1.paths(None)[i].clone()).collect();
    let written = paths.clone();
    let stats_text = args.stats.as_ref().map(|path| {
        paths.push(path.clone());
        let value = if records.len() == 1 { records.remove(0) } else { serde_json::Value::Array(records) };
        serde_json::to_string_pretty(&value).expect("JSON of plain values")
    });
    twister::output::write_all_with(&paths, |k, temp| {
        let Some(&(v, image)) = images.get(k) else {
            let text = stats_text.as_deref().unwrap_or_default();
            return std::fs::write(temp, text).map_err(|e| Error::output(&paths[k], format!("cannot write: {e}")));
        };
        let mut reader = SpoolReader::open(&spools[v])?;
        views[v]
            .1
            .stream_image(image, &paths[k], temp, spools[v].size, &mut |eye, row, x, n| reader.read(eye, row, x, n))
    })?;
    Ok(written)
}
