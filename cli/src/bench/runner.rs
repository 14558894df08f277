//! What the figures share: their configuration, the renderer they run on, and their CSV and
//! PNG outputs.

use std::path::{Path, PathBuf};

use serde::Serialize;
use twister::core::panoramas::projection::Projection;
use twister::core::settings::{Method, Split};
use twister::error::{Error, Result};
use twister::gpu::Renderer;

#[derive(Clone, Debug)]
pub struct FigureConfig {
    pub projection: Projection,
    pub reps: usize,
    pub quick: bool,
    pub assets: PathBuf,
    pub out: PathBuf,
}

impl FigureConfig {
    /// Full runs use the paper's 3168×600 and 5 reps; `--quick` a quarter of the width, 2 reps,
    /// fewer N and slit widths (a smoke test that finishes in a few minutes on 2 cores).
    pub fn new(quick: bool, reps: Option<usize>, assets: PathBuf, out: PathBuf) -> FigureConfig {
        let projection =
            if quick { Projection { width: 792, height: 150, ..Projection::default() } } else { Projection::default() };
        FigureConfig { projection, reps: reps.unwrap_or(if quick { 2 } else { 5 }).max(1), quick, assets, out }
    }

    pub fn fig8_divisions(&self) -> Vec<u32> {
        if self.quick {
            vec![1, 4, 7, 10]
        } else {
            (1..=10).collect()
        }
    }

    pub fn fig10_methods(&self) -> Vec<Method> {
        let fixed: Vec<u32> = if self.quick { vec![1, 4, 7] } else { (1..=7).collect() };
        std::iter::once(Method::Vertex)
            .chain(fixed.into_iter().map(Method::Fixed))
            .chain([Method::Adaptive(Split::Length), Method::Adaptive(Split::Error)])
            .collect()
    }

    pub fn slit_widths(&self) -> Vec<u32> {
        if self.quick {
            vec![1, 8, 64]
        } else {
            vec![1, 2, 4, 8, 16, 32, 64, 128]
        }
    }
}

pub struct Runner<'a> {
    pub renderer: &'a Renderer,
    pub cfg: FigureConfig,
    pub progress: indicatif::ProgressBar,
}

pub fn write_csv(path: &Path, rows: &[impl Serialize]) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r).map_err(|e| Error::output(path, e))?;
    }
    let bytes = w.into_inner().map_err(|e| Error::output(path, e))?;
    twister::output::write_text(path, &String::from_utf8_lossy(&bytes))
}

pub fn write_png(path: &Path, img: image::RgbaImage) -> Result<()> {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let dir = path.parent().unwrap_or(Path::new("."));
    let (w, h) = img.dimensions();
    twister::output::write_images(dir, &[(name, twister::EyeImage { width: w, height: h, rgba: img.into_raw() })])?;
    Ok(())
}
