//! Output layouts and file writing. All outputs of one command are written together or not at
//! all: each under a temporary name beside its place, then moved in; on a failure the earlier
//! outputs are restored. Temporaries left by a killed process are cleaned up by the next run
//! that writes in that folder.
//!
//! | layout | files |
//! |---|---|
//! | `eyes` | `left.png`, `right.png`: W×H each |
//! | `top-bottom` | `stereo.png`: W×2H, left eye on top (the VR players' top-bottom format) |
//! | `twister` | `left_front.png`, `left_back.png`, `right_front.png`, `right_back.png`: W/2×H each, as the paper fed the display. Front is the half centred straight ahead (θ ∈ [−π/2, π/2)); back is the half centred behind, continuous across the seam |

use std::path::{Path, PathBuf};

use image::ImageEncoder;

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

/// The file names of a layout, in the order of [`layout_images`].
pub fn layout_names(layout: Layout) -> Vec<String> {
    match layout {
        Layout::Eyes => vec!["left.png".into(), "right.png".into()],
        Layout::TopBottom => vec!["stereo.png".into()],
        Layout::Twister => {
            ["left", "right"].iter().flat_map(|eye| [format!("{eye}_front.png"), format!("{eye}_back.png")]).collect()
        }
    }
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

/// One output file: where it goes and its bytes.
#[derive(Clone, Debug)]
pub struct OutputFile {
    pub path: PathBuf,
    pub bytes: Vec<u8>,
}

/// An image encoded as PNG.
pub fn png_file(path: PathBuf, img: &EyeImage) -> Result<OutputFile> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&img.rgba, img.width, img.height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::output(&path, format!("cannot encode: {e}")))?;
    Ok(OutputFile { path, bytes })
}

/// The temporary name of an output while it is written: `.NAME.PID.tmp` beside it (and
/// `.NAME.PID.old` for the file it replaces until all are in place).
fn side_name(path: &Path, suffix: &str) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{suffix}", std::process::id()))
}

/// Checks, before anything is rendered, that each path can take an output: its folder exists
/// or can be made, and the path is not a folder, device or pipe. Nothing is written.
pub fn check_outputs(paths: &[&Path]) -> Result<()> {
    for path in paths {
        if path.file_name().is_none() {
            return Err(Error::output(*path, "names no file"));
        }
        if let Ok(meta) = std::fs::metadata(path) {
            if meta.is_dir() {
                return Err(Error::output(*path, "is a folder: cannot write a file there"));
            }
            if !meta.is_file() {
                return Err(Error::output(
                    *path,
                    "is not a regular file (a device or pipe?): twister writes only files",
                ));
            }
        }
        let mut parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        // The nearest existing ancestor must be a folder we can write in (the rest is made when
        // writing): a probe file is made and removed.
        loop {
            match std::fs::metadata(parent) {
                Ok(meta) if meta.is_dir() => {
                    let probe = parent.join(format!(".twister-probe.{}.tmp", std::process::id()));
                    std::fs::write(&probe, b"")
                        .map_err(|e| Error::output(*path, format!("cannot be written in {}: {e}", parent.display())))?;
                    let _ = std::fs::remove_file(&probe);
                    break;
                }
                Ok(_) => return Err(Error::output(parent, "is not a folder: cannot write outputs in it")),
                Err(_) => match parent.parent() {
                    Some(p) if !p.as_os_str().is_empty() => parent = p,
                    _ => break,
                },
            }
        }
    }
    Ok(())
}

/// Removes temporary files left in `dir` by twister processes that no longer run (killed while
/// writing): `.NAME.PID.tmp` whose PID is not alive, and their `.old` twins restored if the
/// output itself is missing.
pub fn clean_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(inner) = name.strip_prefix('.') else { continue };
        let (stem, suffix) = match (inner.strip_suffix(".tmp"), inner.strip_suffix(".old")) {
            (Some(s), _) => (s, "tmp"),
            (_, Some(s)) => (s, "old"),
            _ => continue,
        };
        let Some((output, pid)) = stem.rsplit_once('.') else { continue };
        let Ok(pid) = pid.parse::<u32>() else { continue };
        if pid == std::process::id() || process_alive(pid) {
            continue;
        }
        let path = entry.path();
        let original = dir.join(output);
        if suffix == "old" && !original.exists() {
            let _ = std::fs::rename(&path, &original);
        } else {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Whether a process runs (Linux: /proc; elsewhere assumed alive, so nothing is removed).
fn process_alive(pid: u32) -> bool {
    if Path::new("/proc/self").exists() {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

/// Writes every file, all or nothing: each is written under a temporary name beside its place,
/// then all are moved into place; if any step fails, the files already moved are put back as
/// they were (earlier outputs restored) and the temporaries removed.
pub fn write_all(files: &[OutputFile]) -> Result<()> {
    check_outputs(&files.iter().map(|f| f.path.as_path()).collect::<Vec<_>>())?;
    for f in files {
        if let Some(dir) = f.path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::output(dir, format!("cannot create the output folder: {e}")))?;
            clean_stale_temporaries(dir);
        }
    }
    let mut temps: Vec<PathBuf> = Vec::new();
    let mut moved: Vec<(PathBuf, Option<PathBuf>)> = Vec::new(); // (output, its previous file)
    let result = (|| {
        for f in files {
            let temp = side_name(&f.path, "tmp");
            temps.push(temp.clone());
            std::fs::write(&temp, &f.bytes).map_err(|e| Error::output(&f.path, format!("cannot write: {e}")))?;
        }
        for (f, temp) in files.iter().zip(&temps) {
            let old = f.path.exists().then(|| side_name(&f.path, "old"));
            if let Some(old) = &old {
                std::fs::rename(&f.path, old).map_err(|e| Error::output(&f.path, format!("cannot replace: {e}")))?;
            }
            moved.push((f.path.clone(), old));
            std::fs::rename(temp, &f.path).map_err(|e| Error::output(&f.path, format!("cannot write: {e}")))?;
        }
        Ok(())
    })();
    match result {
        Ok(()) => {
            for (_, old) in &moved {
                if let Some(old) = old {
                    let _ = std::fs::remove_file(old);
                }
            }
        }
        Err(_) => {
            for (path, old) in moved.iter().rev() {
                match old {
                    Some(old) => {
                        let _ = std::fs::rename(old, path);
                    }
                    None => {
                        let _ = std::fs::remove_file(path);
                    }
                }
            }
            for temp in &temps {
                let _ = std::fs::remove_file(temp);
            }
        }
    }
    result
}

/// Writes every image into `dir` (created if missing) all-or-nothing; returns the paths.
pub fn write_images(dir: &Path, images: &[(String, EyeImage)]) -> Result<Vec<PathBuf>> {
    let files = images.iter().map(|(name, img)| png_file(dir.join(name), img)).collect::<Result<Vec<_>>>()?;
    write_all(&files)?;
    Ok(files.into_iter().map(|f| f.path).collect())
}

/// Writes a text file atomically (temporary name, then rename).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_all(&[OutputFile { path: path.to_path_buf(), bytes: text.as_bytes().to_vec() }])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_names_are_the_names_of_the_layout_images() {
        let eye = EyeImage { width: 8, height: 2, rgba: vec![0; 64] };
        let frame = Frame { left: eye.clone(), right: eye, stats: Default::default(), measurement: None };
        for layout in [Layout::Eyes, Layout::TopBottom, Layout::Twister] {
            let names: Vec<String> = layout_images(&frame, layout).into_iter().map(|(n, _)| n).collect();
            assert_eq!(names, layout_names(layout));
        }
    }

    #[test]
    fn a_failed_write_leaves_the_earlier_outputs_and_no_temporaries() {
        let dir = std::env::temp_dir().join(format!("twister-output-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("b.txt")).unwrap(); // a folder where a file should go
        std::fs::write(dir.join("a.txt"), "old").unwrap();
        let files = [
            OutputFile { path: dir.join("a.txt"), bytes: b"new".to_vec() },
            OutputFile { path: dir.join("b.txt"), bytes: b"new".to_vec() },
        ];
        let err = write_all(&files).unwrap_err().to_string();
        assert!(err.contains("b.txt") && err.contains("folder"), "{err}");
        assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "old");
        // Stale temporaries of a dead process are removed; a live one's are kept.
        std::fs::remove_dir_all(dir.join("b.txt")).unwrap();
        let dead = dir.join(".a.txt.4194303.tmp");
        let live = dir.join(format!(".a.txt.{}.tmp", std::process::id()));
        std::fs::write(&dead, "x").unwrap();
        std::fs::write(&live, "x").unwrap();
        write_all(&files).unwrap();
        assert_eq!(std::fs::read_to_string(dir.join("a.txt")).unwrap(), "new");
        assert!(!dead.exists() || process_alive(4194303), "the dead process's temporary is gone");
        let left: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert!(left.iter().all(|n| !n.ends_with(".old")), "{left:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
