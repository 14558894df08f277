//! Output layouts and PNG writing. Files are written under temporary names and renamed into
//! place only when every file of the layout has been written, so a failure leaves no
//! half-written output.
//!
//! | layout | files |
//! |---|---|
//! | `eyes` | `left.png`, `right.png`: W×H each |
//! | `top-bottom` | `stereo.png`: W×2H, left eye on top (the VR players' top-bottom format) |
//! | `twister` | `left_front.png`, `left_back.png`, `right_front.png`, `right_back.png`: W/2×H each, as the paper fed the display. Front is the half centred straight ahead (θ ∈ [−π/2, π/2)); back is the half centred behind, continuous across the seam |

use std::path::{Path, PathBuf};

use crate::core::frame::{EyeImage, Frame};
use crate::error::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    #[default]
    Eyes,
    TopBottom,
    Twister,
}

/// Columns [start, start + width) of an image, wrapping around the panorama.
pub fn columns(img: &EyeImage, start: u32, width: u32) -> EyeImage {
    let mut rgba = Vec::with_capacity((4 * width * img.height) as usize);
    for y in 0..img.height {
        for k in 0..width {
            let x = (start + k) % img.width;
            let i = 4 * (y * img.width + x) as usize;
            rgba.extend_from_slice(&img.rgba[i..i + 4]);
        }
    }
    EyeImage { width, height: img.height, rgba }
}

/// The images of a layout, with their file names.
pub fn layout_images(frame: &Frame, layout: Layout) -> Vec<(String, EyeImage)> {
    match layout {
        Layout::Eyes => vec![("left.png".into(), frame.left.clone()), ("right.png".into(), frame.right.clone())],
        Layout::TopBottom => {
            let mut rgba = frame.left.rgba.clone();
            rgba.extend_from_slice(&frame.right.rgba);
            vec![("stereo.png".into(), EyeImage { width: frame.left.width, height: 2 * frame.left.height, rgba })]
        }
        Layout::Twister => {
            let w = frame.left.width;
            let (quarter, half) = (w / 4, w / 2);
            let mut out = Vec::new();
            for (name, img) in [("left", &frame.left), ("right", &frame.right)] {
                out.push((format!("{name}_front.png"), columns(img, quarter, half)));
                out.push((format!("{name}_back.png"), columns(img, quarter + half, w - half)));
            }
            out
        }
    }
}

/// Writes every image into `dir` (created if missing) all-or-nothing; returns the paths.
pub fn write_images(dir: &Path, images: &[(String, EyeImage)]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, format!("cannot create the output folder: {e}")))?;
    let mut temps = Vec::new();
    let result = (|| {
        for (name, img) in images {
            let final_path = dir.join(name);
            let temp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
            temps.push((temp.clone(), final_path.clone()));
            image::save_buffer_with_format(
                &temp,
                &img.rgba,
                img.width,
                img.height,
                image::ColorType::Rgba8,
                image::ImageFormat::Png,
            )
            .map_err(|e| Error::output(&final_path, format!("cannot write: {e}")))?;
        }
        for (temp, final_path) in &temps {
            std::fs::rename(temp, final_path).map_err(|e| Error::output(final_path, format!("cannot write: {e}")))?;
        }
        Ok(temps.iter().map(|(_, f)| f.clone()).collect())
    })();
    if result.is_err() {
        for (temp, _) in &temps {
            let _ = std::fs::remove_file(temp);
        }
    }
    result
}

/// Writes a text file atomically (temporary name, then rename).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| Error::output(parent, format!("cannot create folder: {e}")))?;
    }
    let temp = path.with_extension(format!("{}.tmp", std::process::id()));
    std::fs::write(&temp, text).and_then(|_| std::fs::rename(&temp, path)).map_err(|e| {
        let _ = std::fs::remove_file(&temp);
        Error::output(path, format!("cannot write: {e}"))
    })
}
