//! What the live window shows of a frame (`twister view`; the `display` stage, twin
//! `cpu::display`): the panoramas stacked, the TWISTER display's four halves, or a look-around
//! view into each eye's panorama as a headset shows it. A look-around pixel takes its colour
//! from where the eye's panorama shows a point far along its direction: the projection's own
//! forward map (seed 002 eq. 1–4 on the cylinder; the sphere's, the fisheye's, the cubemap's),
//! so every panorama is previewed as it is drawn.

use crate::core::panoramas::projection::Projection;

/// How the frame is shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DisplayMode {
    /// The eyes' images stacked, left above right (or one image: the error heatmap).
    #[default]
    Panorama,
    /// The TWISTER display's four W/2×H inputs (the `twister` layout's halves) in a 2×2 grid:
    /// front and back, the left eye's on top.
    Halves,
    /// A perspective view from the centre into each eye's panorama, side by side.
    LookSideBySide,
    /// The same as a red-cyan anaglyph (left eye red).
    LookAnaglyph,
}

impl DisplayMode {
    pub fn code(self) -> u32 {
        match self {
            DisplayMode::Panorama => 0,
            DisplayMode::Halves => 1,
            DisplayMode::LookSideBySide => 2,
            DisplayMode::LookAnaglyph => 3,
        }
    }

    /// The mode of a code ([`DisplayMode::code`]).
    pub fn from_code(code: u32) -> Option<DisplayMode> {
        [DisplayMode::Panorama, DisplayMode::Halves, DisplayMode::LookSideBySide, DisplayMode::LookAnaglyph]
            .into_iter()
            .find(|m| m.code() == code)
    }

    pub fn is_look(self) -> bool {
        matches!(self, DisplayMode::LookSideBySide | DisplayMode::LookAnaglyph)
    }

    pub fn name(self) -> &'static str {
        match self {
            DisplayMode::Panorama => "panorama",
            DisplayMode::Halves => "display halves",
            DisplayMode::LookSideBySide => "look-around",
            DisplayMode::LookAnaglyph => "anaglyph",
        }
    }
}

/// A look-around view: the gaze (radians; yaw to the right, pitch up) and the horizontal field
/// of view (degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    pub yaw: f32,
    pub pitch: f32,
    pub fov_deg: f32,
}

impl Default for Look {
    fn default() -> Look {
        Look { yaw: 0.0, pitch: 0.0, fov_deg: 90.0 }
    }
}

/// The far distance, metres, of the point whose pixel a look-around direction takes: far enough
/// that each eye's offset is its limit at infinity.
pub fn look_far(p: &Projection) -> f32 {
    1.0e3 * p.screen_radius.max(1.0)
}

/// The rectangle (x, y, width, height) a `content` size takes in a `target` size, scaled to fit
/// with its aspect kept and centred; whole pixels where it is drawn at its own size.
pub fn fit_area(content: [u32; 2], target: [u32; 2]) -> [f32; 4] {
    let (cw, ch) = (content[0].max(1) as f32, content[1].max(1) as f32);
    let (tw, th) = (target[0] as f32, target[1] as f32);
    let scale = (tw / cw).min(th / ch);
    let (w, h) = (cw * scale, ch * scale);
    [((tw - w) / 2.0).floor(), ((th - h) / 2.0).floor(), w, h]
}

/// What a frame's display needs: the mode, the look, the image and where it goes.
#[derive(Clone, Copy, Debug)]
pub struct DisplayView {
    pub mode: DisplayMode,
    pub look: Look,
    /// Each layer's size and how many layers (2: the eyes; 1: one image).
    pub image: [u32; 2],
    pub layers: u32,
    /// Texels per row of the image's buffer.
    pub row_texels: u32,
    /// The target's size.
    pub target: [u32; 2],
    /// The overlay's place (x, y, width, height), if any.
    pub overlay: Option<[u32; 4]>,
    /// Whether the target encodes sRGB itself.
    pub srgb_target: bool,
}

impl DisplayView {
    /// Where the image goes: the whole target for the display's halves (a display's inputs fill
    /// its screen) and the look-around views; else fitted with its aspect kept.
    pub fn area(&self) -> [f32; 4] {
        let [w, h] = self.image;
        match self.mode {
            DisplayMode::Halves => [0.0, 0.0, self.target[0] as f32, self.target[1] as f32],
            m if m.is_look() => [0.0, 0.0, self.target[0] as f32, self.target[1] as f32],
            _ => fit_area([w, h * self.layers], self.target),
        }
    }
}

/// Whether a panorama can be looked around in (a CAVE's walls are perspectives already).
pub fn can_look(p: &Projection) -> bool {
    !p.model().drawn_as_pinhole()
}
