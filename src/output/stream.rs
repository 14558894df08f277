//! A frame's image encoded row by row as the rows arrive (a tiled frame's, `cli::tiled`): PNG
//! through the png crate's stream writer, JPEG through jpeg-encoder's baseline encoder, which
//! pulls rows; neither holds the image.

use std::path::Path;

use super::{Encoding, ImageFormat, JPEG_XMP_NAMESPACE};
use crate::error::{Error, Result};

/// Encodes an image of `size` into file `temp` (the output `path`, for errors) row by row as
/// `row(y)` gives them (RGBA, top first): PNG through a stream writer, JPEG through a
/// row-pulling baseline encoder (both hold a few rows, never the image); with the XMP packet.
pub fn stream_image(
    path: &Path,
    temp: &Path,
    [width, height]: [u32; 2],
    encoding: &Encoding,
    mut row: impl FnMut(u32) -> Result<Vec<u8>>,
) -> Result<()> {
    use std::io::Write;
    let fail = |e: &dyn std::fmt::Display| Error::output(path, format!("cannot encode: {e}"));
    let file = std::fs::File::create(temp).map_err(|e| Error::output(path, format!("cannot write: {e}")))?;
    let out = std::io::BufWriter::with_capacity(1 << 20, file);
    match encoding.format {
        ImageFormat::Png => {
            let mut writer = super::png_writer(out, [width, height], encoding).map_err(|e| fail(&e))?;
            let mut stream = writer.stream_writer().map_err(|e| fail(&e))?;
            for y in 0..height {
                stream.write_all(&row(y)?).map_err(|e| fail(&e))?;
            }
            stream.finish().map_err(|e| fail(&e))?;
        }
        ImageFormat::Jpg => {
            let (w, h) = match (u16::try_from(width), u16::try_from(height)) {
                (Ok(w), Ok(h)) => (w, h),
                _ => {
                    return Err(fail(&format_args!(
                        "{width}x{height} is beyond JPEG's 65535 pixels a side (PNG takes it)"
                    )))
                }
            };
            let mut encoder = jpeg_encoder::Encoder::new(out, encoding.quality.clamp(1, 100));
            if let Some(xmp) = &encoding.xmp {
                encoder.add_app_segment(1, [JPEG_XMP_NAMESPACE, xmp.as_bytes()].concat()).map_err(|e| fail(&e))?;
            }
            let source = RowSource {
                width: w,
                height: h,
                row: std::cell::RefCell::new(&mut row),
                last: Default::default(),
                error: Default::default(),
            };
            encoder.encode_image(&source).map_err(|e| fail(&e))?;
            if let Some(e) = source.error.into_inner() {
                return Err(e);
            }
        }
    }
    Ok(())
}

/// Rows for the JPEG encoder, pulled as it needs them (it asks for the last row again to pad the
/// last block row: the last row read is kept); an error is kept and reported after.
struct RowSource<'a, F: FnMut(u32) -> Result<Vec<u8>>> {
    width: u16,
    height: u16,
    row: std::cell::RefCell<&'a mut F>,
    last: std::cell::RefCell<Option<(u16, Vec<u8>)>>,
    error: std::cell::RefCell<Option<Error>>,
}

impl<F: FnMut(u32) -> Result<Vec<u8>>> jpeg_encoder::ImageBuffer for &RowSource<'_, F> {
    fn get_jpeg_color_type(&self) -> jpeg_encoder::JpegColorType {
        jpeg_encoder::JpegColorType::Ycbcr
    }
    fn width(&self) -> u16 {
        self.width
    }
    fn height(&self) -> u16 {
        self.height
    }
    fn fill_buffers(&self, y: u16, buffers: &mut [Vec<u8>; 4]) {
        let mut last = self.last.borrow_mut();
        if last.as_ref().is_none_or(|(at, _)| *at != y) {
            let rgba = match (self.row.borrow_mut())(y as u32) {
                Ok(rgba) => rgba,
                Err(e) => {
                    self.error.borrow_mut().get_or_insert(e);
                    vec![0; 4 * self.width as usize]
                }
            };
            *last = Some((y, rgba));
        }
        let (_, rgba) = last.as_ref().expect("just read");
        for px in rgba.chunks_exact(4) {
            let (luma, cb, cr) = jpeg_encoder::rgb_to_ycbcr(px[0], px[1], px[2]);
            buffers[0].push(luma);
            buffers[1].push(cb);
            buffers[2].push(cr);
        }
    }
}

/// An OpenEXR image of `size` with `channels` float channels (1: `Z`, depth; 3: R, G, B, linear
/// colour) encoded into file `temp` (the output `path`) as `row(y)` gives its rows (top first,
/// `channels` values a pixel): uncompressed scan lines written in order, a row held at a time.
pub fn stream_exr(
    path: &Path,
    temp: &Path,
    [width, height]: [u32; 2],
    channels: usize,
    row: impl FnMut(u32) -> Result<Vec<f32>> + Send,
) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    // The row the encoder reads now (it asks pixel by pixel, row after row), and the first error.
    let state = std::sync::Mutex::new((u32::MAX, Vec::<f32>::new(), row, None::<Error>));
    let at = |p: Vec2<usize>, c: usize| -> f32 {
        let mut s = state.lock().unwrap_or_else(|e| e.into_inner());
        let (ref mut y, ref mut values, ref mut read, ref mut error) = *s;
        if *y != p.y() as u32 {
            *y = p.y() as u32;
            *values = read(*y).unwrap_or_else(|e| {
                error.get_or_insert(e);
                vec![0.0; channels * width as usize]
            });
        }
        values.get(p.x() * channels + c).copied().unwrap_or(0.0)
    };
    let size = (width as usize, height as usize);
    let written = if channels == 1 {
        let image =
            Image::from_channels(size, SpecificChannels::build().with_channel("Z").with_pixel_fn(|p| (at(p, 0),)));
        image.write().to_file(temp)
    } else {
        let image = Image::from_channels(size, SpecificChannels::rgb(|p| (at(p, 0), at(p, 1), at(p, 2))));
        image.write().to_file(temp)
    };
    written.map_err(|e| Error::output(path, format!("cannot encode OpenEXR: {e}")))?;
    match state.into_inner().unwrap_or_else(|e| e.into_inner()).3 {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
