//! Output layouts, image formats, metadata and file writing. All outputs of one command are
//! written together or not at all: each under a temporary name beside its place, then moved
//! in; on a failure the earlier outputs are restored. Temporaries left by a killed process are
//! cleaned up by the next run that writes in that folder.
//!
//! | layout | files (`.png` or `.jpg`) |
//! |---|---|
//! | `eyes` | `left.png`, `right.png`: W×H each |
//! | `top-bottom` | `stereo_TB.png`: W×2H, left eye on top (the VR players' top-bottom format; `_TB` is the suffix players look for) |
//! | `side-by-side` | `stereo_LR.png`: 2W×H, left eye on the left (`_LR`) |
//! | `twister` | `left_front.png`, `left_back.png`, `right_front.png`, `right_back.png`: W/2×H each, as the paper fed the display. Front is the half centred straight ahead (θ ∈ [−π/2, π/2)); back is the half centred behind, continuous across the seam |
//!
//! Depth (`--depth`, [`depth_images`]) follows the layout: `left_depth.exr` and
//! `right_depth.exr` (eyes, twister), `depth_TB.exr`, `depth_LR.exr`: one 32-bit float channel
//! `Z`, the distance in metres from each pixel's eye point along its ray, +∞ where no surface is.
//!
//! Full-sphere images carry Google's photo-sphere XMP ([`gpano_xmp`]): in PNG as an iTXt chunk
//! `XML:com.adobe.xmp`, in JPEG as an APP1 segment.

use std::path::{Path, PathBuf};

use crate::core::frame::{EyeImage, Frame};
use crate::core::panoramas::panorama::{EyePacking, PanoramaKind};
use crate::error::{Error, Result};

mod stream;
pub use stream::{stream_exr, stream_image};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    #[default]
    Eyes,
    TopBottom,
    SideBySide,
    Twister,
    /// The cubemap's twelve faces in one strip, the left eye's six then the right eye's, each
    /// eye's in the grid's order (right, left, up, down, front, back): Meta's 360 photo format.
    #[serde(rename = "12x1")]
    Strip12,
}

crate::choices!(Layout {
    Eyes => ("eyes", "One image per eye"),
    TopBottom => ("top-bottom", "One image, the left eye above the right"),
    SideBySide => ("side-by-side", "One image, the left eye beside the right"),
    Twister => ("twister", "Four images: each eye's front and back halves"),
    Strip12 => ("12x1", "The cubemap's twelve faces in one strip (Meta's 360 photo format)"),
});

crate::choices!(ImageFormat {
    Png => ("png", "PNG"),
    Jpg => ("jpg", "JPEG at the chosen quality"),
});

impl Layout {
    /// The layout a panorama is written in by default (its [`EyePacking`]): the eyes apart for
    /// the cylinder (the TWISTER display's inputs), top-bottom for the sphere (what VR players
    /// take), side by side for VR180.
    pub fn default_for(panorama: PanoramaKind) -> Layout {
        match panorama.model().eye_packing() {
            EyePacking::Separate => Layout::Eyes,
            EyePacking::TopBottom => Layout::TopBottom,
            EyePacking::SideBySide => Layout::SideBySide,
        }
    }
}

/// The image file format (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImageFormat {
    #[default]
    Png,
    Jpg,
}

impl ImageFormat {
    pub fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Jpg => "jpg",
        }
    }
}

/// How images are encoded: the format, the JPEG quality (1–100) and the XMP packet each file
/// carries (the sphere's GPano metadata); PNGs deflated fast (a sequence's frames: about a
/// third of the time for files a little larger) or balanced.
#[derive(Clone, Debug, PartialEq)]
pub struct Encoding {
    pub format: ImageFormat,
    pub quality: u8,
    pub xmp: Option<String>,
    pub fast: bool,
}

impl Default for Encoding {
    fn default() -> Self {
        Encoding { format: ImageFormat::Png, quality: 90, xmp: None, fast: false }
    }
}

/// The image with every pixel outside the projection's image (the fisheye's circle) transparent
/// (RGBA 0, 0, 0, 0): `--alpha`.
pub fn transparent_outside(img: &EyeImage, projection: &crate::core::panoramas::projection::Projection) -> EyeImage {
    let mut out = img.clone();
    for (i, px) in out.rgba.chunks_exact_mut(4).enumerate() {
        let (x, y) = ((i as u32 % img.width) as f32 + 0.5, (i as u32 / img.width) as f32 + 0.5);
        if !projection.shows_pixel(x, y) {
            px.copy_from_slice(&[0; 4]);
        }
    }
    out
}

/// The file names of a layout, in the order of [`layout_images`]. The combined layouts carry
/// the tags VR players detect: `_360` or `_180` for the panorama, then `_TB` or `_LR`.
pub fn layout_names(layout: Layout, format: ImageFormat, panorama: PanoramaKind) -> Vec<String> {
    let ext = format.extension();
    let tag = panorama.player_tag().map_or(String::new(), |t| format!("_{t}"));
    match layout {
        Layout::Eyes => vec![format!("left.{ext}"), format!("right.{ext}")],
        Layout::TopBottom => vec![format!("stereo{tag}_TB.{ext}")],
        Layout::SideBySide => vec![format!("stereo{tag}_LR.{ext}")],
        Layout::Twister => ["left", "right"]
            .iter()
            .flat_map(|eye| [format!("{eye}_front.{ext}"), format!("{eye}_back.{ext}")])
            .collect(),
        Layout::Strip12 => vec![format!("stereo{tag}_12x1.{ext}")],
    }
}

/// One piece of a layout image's row: the eye (0 left, 1 right), the eye image's row, its
/// first column and how many columns.
pub type RowPiece = (usize, u32, u32, u32);

/// The sizes of a layout's images, in the order of [`layout_names`], for eyes of `w` × `h`.
pub fn layout_sizes(layout: Layout, [w, h]: [u32; 2]) -> Vec<[u32; 2]> {
    match layout {
        Layout::Eyes => vec![[w, h]; 2],
        Layout::TopBottom => vec![[w, 2 * h]],
        Layout::SideBySide => vec![[2 * w, h]],
        Layout::Twister => vec![[w / 2, h], [w - w / 2, h], [w / 2, h], [w - w / 2, h]],
        Layout::Strip12 => vec![[4 * w, h / 2]],
    }
}

/// Row `row` of image `image` of a layout, as pieces of the eyes' rows (eyes of `w` × `h`): the
/// one recipe that both the images in memory and the streamed ones of a tiled frame follow.
pub fn layout_row(layout: Layout, image: usize, row: u32, [w, h]: [u32; 2]) -> Vec<RowPiece> {
    match layout {
        Layout::Eyes => vec![(image, row, 0, w)],
        Layout::TopBottom => vec![((row >= h) as usize, row % h, 0, w)],
        Layout::SideBySide => vec![(0, row, 0, w), (1, row, 0, w)],
        // Each eye's middle half (its front), then the outer halves (its back, wrapping).
        Layout::Twister => {
            let (eye, half) = (image / 2, w / 2);
            let (start, width) = if image % 2 == 0 { (w / 4, half) } else { (w / 4 + half, w - half) };
            let first = width.min(w - start);
            let mut pieces = vec![(eye, row, start, first)];
            if width > first {
                pieces.push((eye, row, 0, width - first));
            }
            pieces
        }
        // The left eye's six faces, then the right eye's, each in the grid's order.
        Layout::Strip12 => {
            let face = w / 3;
            (0..12).map(|k| (k / 6, (k % 6 / 3) as u32 * face + row, (k % 3) as u32 * face, face)).collect()
        }
    }
}

/// A layout image's texels (`per_texel` values each) from both eyes' (rows of `w`).
fn assemble<T: Copy>(eyes: [&[T]; 2], per_texel: usize, layout: Layout, eye_size: [u32; 2], image: usize) -> Vec<T> {
    let [iw, ih] = layout_sizes(layout, eye_size)[image];
    let w = eye_size[0] as usize;
    let mut out = Vec::with_capacity(iw as usize * ih as usize * per_texel);
    for row in 0..ih {
        for (eye, src_row, x0, n) in layout_row(layout, image, row, eye_size) {
            let start = (src_row as usize * w + x0 as usize) * per_texel;
            out.extend_from_slice(&eyes[eye][start..start + n as usize * per_texel]);
        }
    }
    out
}

/// The images of a layout, with their file names.
pub fn layout_images(
    frame: &Frame,
    layout: Layout,
    format: ImageFormat,
    panorama: PanoramaKind,
) -> Vec<(String, EyeImage)> {
    let size = [frame.left.width, frame.left.height];
    let eyes = [frame.left.rgba.as_slice(), frame.right.rgba.as_slice()];
    layout_names(layout, format, panorama)
        .into_iter()
        .zip(layout_sizes(layout, size))
        .enumerate()
        .map(|(k, (name, [width, height]))| {
            (name, EyeImage { width, height, rgba: assemble(eyes, 4, layout, size, k) })
        })
        .collect()
}

/// A single-channel float image (depth).
#[derive(Clone, Debug, PartialEq)]
pub struct DepthImage {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

/// The depth files of a layout (see the module doc), from a frame rendered with
/// `measure.depth`; None without depth. The eyes apart for the layouts of several images.
pub fn depth_images(frame: &Frame, layout: Layout) -> Option<Vec<(String, DepthImage)>> {
    let [left, right] = frame.depth.as_ref()?;
    let size = [frame.left.width, frame.left.height];
    let layout = match layout {
        Layout::Twister => Layout::Eyes,
        other => other,
    };
    let images = layout_sizes(layout, size).into_iter().enumerate().map(|(k, [width, height])| DepthImage {
        width,
        height,
        values: assemble([left.as_slice(), right.as_slice()], 1, layout, size, k),
    });
    Some(depth_names(layout).into_iter().zip(images).collect())
}

/// The names [`depth_images`] gives a layout.
pub fn depth_names(layout: Layout) -> Vec<String> {
    match layout {
        Layout::Eyes | Layout::Twister => vec!["left_depth.exr".into(), "right_depth.exr".into()],
        Layout::TopBottom => vec!["depth_TB.exr".into()],
        Layout::SideBySide => vec!["depth_LR.exr".into()],
        Layout::Strip12 => vec!["depth_12x1.exr".into()],
    }
}

/// Google's photo-sphere XMP (GPano) for an equirectangular image of `width` × `height` pixels
/// per eye: what Google Photos, Facebook, Kuula and most VR photo viewers read to show an image
/// as a sphere. The full sphere is the whole panorama; VR180's image is its front half, cropped
/// from a panorama twice as wide ([`gpano_xmp_cropped`]).
pub fn gpano_xmp(panorama: PanoramaKind, width: u32, height: u32) -> String {
    let full_width = (width as f32 / panorama.turn_share()).round() as u32;
    gpano_xmp_cropped([width, height], [full_width, height], [(full_width - width) / 2, 0])
}

/// GPano for an image of `cropped` pixels at `left_top` in a full panorama of `full` pixels.
pub fn gpano_xmp_cropped(cropped: [u32; 2], full: [u32; 2], left_top: [u32; 2]) -> String {
    format!(
        concat!(
            "<?xpacket begin=\"\u{feff}\" id=\"W5M0MpCehiHzreSzNTczkc9d\"?>\n",
            "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\" x:xmptk=\"twister\">\n",
            " <rdf:RDF xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n",
            "  <rdf:Description rdf:about=\"\" xmlns:GPano=\"http://ns.google.com/photos/1.0/panorama/\">\n",
            "   <GPano:ProjectionType>equirectangular</GPano:ProjectionType>\n",
            "   <GPano:UsePanoramaViewer>True</GPano:UsePanoramaViewer>\n",
            "   <GPano:CroppedAreaImageWidthPixels>{w}</GPano:CroppedAreaImageWidthPixels>\n",
            "   <GPano:CroppedAreaImageHeightPixels>{h}</GPano:CroppedAreaImageHeightPixels>\n",
            "   <GPano:FullPanoWidthPixels>{fw}</GPano:FullPanoWidthPixels>\n",
            "   <GPano:FullPanoHeightPixels>{fh}</GPano:FullPanoHeightPixels>\n",
            "   <GPano:CroppedAreaLeftPixels>{left}</GPano:CroppedAreaLeftPixels>\n",
            "   <GPano:CroppedAreaTopPixels>{top}</GPano:CroppedAreaTopPixels>\n",
            "  </rdf:Description>\n",
            " </rdf:RDF>\n",
            "</x:xmpmeta>\n",
            "<?xpacket end=\"w\"?>"
        ),
        w = cropped[0],
        h = cropped[1],
        fw = full[0],
        fh = full[1],
        left = left_top[0],
        top = left_top[1],
    )
}

/// The namespace line that opens an XMP APP1 segment of a JPEG.
pub const JPEG_XMP_NAMESPACE: &[u8] = b"http://ns.adobe.com/xap/1.0/\0";

/// One output file: where it goes and its bytes.
#[derive(Clone, Debug)]
pub struct OutputFile {
    pub path: PathBuf,
    pub bytes: Vec<u8>,
}

/// An image encoded as PNG (no metadata).
pub fn png_file(path: PathBuf, img: &EyeImage) -> Result<OutputFile> {
    image_file(path, img, &Encoding::default())
}

/// An image encoded as `encoding` says: PNG (RGBA, the XMP as an iTXt chunk
/// `XML:com.adobe.xmp`) or JPEG (RGB at the quality, the XMP as an APP1 segment after the JFIF
/// header).
pub fn image_file(path: PathBuf, img: &EyeImage, encoding: &Encoding) -> Result<OutputFile> {
    let fail = |e: &dyn std::fmt::Display| Error::output(&path, format!("cannot encode: {e}"));
    let mut bytes = Vec::new();
    match encoding.format {
        ImageFormat::Png => {
            let mut writer = png_writer(&mut bytes, [img.width, img.height], encoding).map_err(|e| fail(&e))?;
            writer.write_image_data(&img.rgba).map_err(|e| fail(&e))?;
            writer.finish().map_err(|e| fail(&e))?;
        }
        ImageFormat::Jpg => {
            use image::ImageEncoder;
            let rgb: Vec<u8> = img.rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
            let mut jpeg = Vec::new();
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, encoding.quality.clamp(1, 100))
                .write_image(&rgb, img.width, img.height, image::ExtendedColorType::Rgb8)
                .map_err(|e| fail(&e))?;
            bytes = match &encoding.xmp {
                Some(xmp) => with_jpeg_xmp(&jpeg, xmp).ok_or_else(|| fail(&"the XMP packet is too long for JPEG"))?,
                None => jpeg,
            };
        }
    }
    Ok(OutputFile { path, bytes })
}

/// A PNG's writer with its header written: RGBA8, deflated fast or balanced, with the XMP
/// packet (an iTXt chunk) where the encoding has one.
fn png_writer<W: std::io::Write>(
    out: W,
    [width, height]: [u32; 2],
    encoding: &Encoding,
) -> Result<png::Writer<W>, png::EncodingError> {
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    if encoding.fast {
        encoder.set_compression(png::Compression::Fast);
    }
    if let Some(xmp) = &encoding.xmp {
        encoder.add_itxt_chunk("XML:com.adobe.xmp".into(), xmp.clone())?;
    }
    encoder.write_header()
}

/// A JPEG with an XMP APP1 segment inserted after SOI and the APP0 (JFIF) segment, if any.
/// None if the packet does not fit one segment (64 KiB).
fn with_jpeg_xmp(jpeg: &[u8], xmp: &str) -> Option<Vec<u8>> {
    let payload = [JPEG_XMP_NAMESPACE, xmp.as_bytes()].concat();
    let length = u16::try_from(payload.len() + 2).ok()?;
    // After SOI (2 bytes) and an APP0 segment (FF E0, length) when present.
    let mut at = 2;
    if jpeg.len() >= 6 && jpeg[2] == 0xFF && jpeg[3] == 0xE0 {
        at = 4 + u16::from_be_bytes([jpeg[4], jpeg[5]]) as usize;
    }
    let mut out = Vec::with_capacity(jpeg.len() + payload.len() + 4);
    out.extend_from_slice(&jpeg[..at]);
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&length.to_be_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&jpeg[at..]);
    Some(out)
}

/// A depth image as OpenEXR: one 32-bit float channel `Z`, uncompressed scan lines.
pub fn exr_file(path: PathBuf, depth: &DepthImage) -> Result<OutputFile> {
    use exr::prelude::*;
    let (w, h) = (depth.width as usize, depth.height as usize);
    let channel =
        SpecificChannels::build().with_channel("Z").with_pixel_fn(|p: Vec2<usize>| (depth.values[p.y() * w + p.x()],));
    let image = Image::from_channels((w, h), channel);
    exr_output(path, |cursor| image.write().to_buffered(cursor))
}

/// An eye's linear colour as OpenEXR: 32-bit float channels R, G, B, uncompressed scan lines.
pub fn hdr_exr_file(path: PathBuf, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<OutputFile> {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = rgb[p.y() * w + p.x()];
        (r, g, b)
    });
    let image = Image::from_channels((w, height as usize), channels);
    exr_output(path, |cursor| image.write().to_buffered(cursor))
}

/// An OpenEXR output from what `write` encodes into memory.
fn exr_output(
    path: PathBuf,
    write: impl FnOnce(&mut std::io::Cursor<Vec<u8>>) -> exr::error::UnitResult,
) -> Result<OutputFile> {
    let mut cursor = std::io::Cursor::new(Vec::new());
    write(&mut cursor).map_err(|e| crate::error::Error::output(&path, format!("cannot encode OpenEXR: {e}")))?;
    Ok(OutputFile { path, bytes: cursor.into_inner() })
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
    let paths: Vec<PathBuf> = files.iter().map(|f| f.path.clone()).collect();
    write_all_with(&paths, |k, temp| {
        std::fs::write(temp, &files[k].bytes).map_err(|e| Error::output(&files[k].path, format!("cannot write: {e}")))
    })
}

/// Writes the files at `paths` all or none, as [`write_all`]: `write(k, temporary)` writes file
/// k's contents into a temporary beside it (streamed, for a tiled frame's images), then all are
/// put in place together.
pub fn write_all_with(paths: &[PathBuf], write: impl Fn(usize, &Path) -> Result<()>) -> Result<()> {
    check_outputs(&paths.iter().map(|p| p.as_path()).collect::<Vec<_>>())?;
    for path in paths {
        if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| Error::output(dir, format!("cannot create the output folder: {e}")))?;
            clean_stale_temporaries(dir);
        }
    }
    let mut temps: Vec<PathBuf> = Vec::new();
    let mut moved: Vec<(PathBuf, Option<PathBuf>)> = Vec::new(); // (output, its previous file)
    let result = (|| {
        for (k, path) in paths.iter().enumerate() {
            let temp = side_name(path, "tmp");
            temps.push(temp.clone());
            write(k, &temp)?;
        }
        for (path, temp) in paths.iter().zip(&temps) {
            let old = path.exists().then(|| side_name(path, "old"));
            if let Some(old) = &old {
                std::fs::rename(path, old).map_err(|e| Error::output(path, format!("cannot replace: {e}")))?;
            }
            moved.push((path.clone(), old));
            std::fs::rename(temp, path).map_err(|e| Error::output(path, format!("cannot write: {e}")))?;
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
    fn layouts_are_named_in_kebab_and_snake_case_as_the_json_spells_them() {
        use crate::core::choice::Choice;
        assert_eq!(Layout::from_name("Top-Bottom"), Some(Layout::TopBottom));
        assert_eq!(Layout::from_name("top_bottom"), Some(Layout::TopBottom));
        assert_eq!(serde_json::to_value(Layout::Strip12).unwrap(), Layout::Strip12.name());
    }

    #[test]
    fn layout_names_are_the_names_of_the_layout_images() {
        let eye = EyeImage { width: 6, height: 4, rgba: vec![0; 96] };
        let frame = Frame {
            left: eye.clone(),
            right: eye,
            stats: Default::default(),
            measurement: None,
            depth: None,
            positions: None,
            hdr: None,
        };
        for layout in [Layout::Eyes, Layout::TopBottom, Layout::SideBySide, Layout::Twister, Layout::Strip12] {
            for format in [ImageFormat::Png, ImageFormat::Jpg] {
                for &panorama in PanoramaKind::ALL {
                    let images = layout_images(&frame, layout, format, panorama);
                    let names: Vec<String> = images.into_iter().map(|(n, _)| n).collect();
                    assert_eq!(names, layout_names(layout, format, panorama));
                }
            }
        }
    }

    /// The 12×1 strip holds each eye's faces, cut from its grid by their cells (right, left, up /
    /// down, front, back), the left eye's first, every pixel in place.
    #[test]
    fn the_strip_of_twelve_faces_cuts_each_eyes_grid_in_the_grids_order() {
        let face = 3u32;
        let (w, h) = (3 * face, 2 * face);
        // Each pixel holds its eye, its face (from its cell) and its place in the face.
        let grid = |eye: u8| {
            let rgba = (0..w * h)
                .flat_map(|i| {
                    let (x, y) = (i % w, i / w);
                    let f = (3 * (y / face) + x / face) as u8;
                    [eye, f, (x % face) as u8, (y % face) as u8]
                })
                .collect();
            EyeImage { width: w, height: h, rgba }
        };
        let frame = Frame {
            left: grid(0),
            right: grid(1),
            stats: Default::default(),
            measurement: None,
            depth: Some([(0..w * h).map(|i| i as f32).collect(), (0..w * h).map(|i| -(i as f32)).collect()]),
            positions: None,
            hdr: None,
        };
        let images = layout_images(
            &frame,
            Layout::Strip12,
            ImageFormat::Png,
            crate::core::panoramas::projection::Projection::cubemap(48).panorama,
        );
        assert_eq!(images.len(), 1);
        let (name, strip) = &images[0];
        assert_eq!((name.as_str(), strip.width, strip.height), ("stereo_cubemap_12x1.png", 12 * face, face));
        for (i, px) in strip.rgba.chunks_exact(4).enumerate() {
            let (x, y) = (i as u32 % strip.width, i as u32 / strip.width);
            let k = x / face;
            assert_eq!(px, [(k / 6) as u8, (k % 6) as u8, (x % face) as u8, y as u8], "strip pixel ({x}, {y})");
        }
        let depth = depth_images(&frame, Layout::Strip12).unwrap();
        assert_eq!(depth[0].0, "depth_12x1.exr");
        // The right eye's down face (its fourth: cell (0, 1)), second row, first column.
        let at = depth[0].1.values[(face * 12 + 9 * face) as usize];
        assert_eq!(at, -(((face + 1) * w) as f32));
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
