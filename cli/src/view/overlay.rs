//! The window's overlay: lines of text (embedded-graphics' mono font) on a dark, half-clear
//! panel, as RGBA texels for the display stage to blend over the image.

use embedded_graphics::mono_font::{ascii::FONT_7X13, MonoTextStyle};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};

const LINE_H: u32 = 14;
const MARGIN: u32 = 6;
const PANEL: u32 = 0xb0_10_10_10; // alpha 0xb0, dark grey (RGBA bytes packed, R low)

/// An RGBA canvas (R in the low byte) that embedded-graphics draws into.
struct Canvas {
    width: u32,
    height: u32,
    texels: Vec<u32>,
}

impl OriginDimensions for Canvas {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for Canvas {
    type Color = Rgb888;
    type Error = std::convert::Infallible;
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && (p.x as u32) < self.width && (p.y as u32) < self.height {
                let word = c.r() as u32 | (c.g() as u32) << 8 | (c.b() as u32) << 16 | 0xff << 24;
                self.texels[(p.y as u32 * self.width + p.x as u32) as usize] = word;
            }
        }
        Ok(())
    }
}

/// The overlay of `lines`: its size and texels.
pub fn overlay(lines: &[String]) -> ([u32; 2], Vec<u32>) {
    let chars = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) as u32;
    let width = 2 * MARGIN + 7 * chars;
    let height = 2 * MARGIN + LINE_H * lines.len() as u32;
    let mut canvas = Canvas { width, height, texels: vec![PANEL; (width * height) as usize] };
    let style = MonoTextStyle::new(&FONT_7X13, Rgb888::new(235, 235, 235));
    for (k, line) in lines.iter().enumerate() {
        let at = Point::new(MARGIN as i32, (MARGIN + k as u32 * LINE_H) as i32);
        // Characters the font lacks are drawn as its replacement glyph.
        Text::with_baseline(line, at, style, Baseline::Top).draw(&mut canvas).ok();
    }
    ([width, height], canvas.texels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_overlay_holds_its_text_on_the_panel() {
        let ([w, h], texels) = overlay(&["12.5 fps".to_string(), "adaptive".to_string()]);
        assert_eq!((w, h), (2 * MARGIN + 7 * 8, 2 * MARGIN + 2 * LINE_H));
        let text = texels.iter().filter(|&&t| t != PANEL).count();
        // Glyph pixels, and only inside the text's lines.
        assert!(text > 40 && text < (w * h) as usize / 3, "{text} text pixels");
        assert!(texels[..(MARGIN * w) as usize].iter().all(|&t| t == PANEL), "the margin is panel");
    }
}
