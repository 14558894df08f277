//! The name of a panorama, as a setting chooses it (`--panorama`, `view.projection.panorama`):
//! [`PanoramaKind`]. Its type, with the maps, is the registry's (`core::panoramas::registry`).

/// The panoramas twister renders (`--panorama`): the name a setting chooses. Its order is the
/// registry's and its index the panorama's code in the WGSL projection uniform.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PanoramaKind {
    /// The TWISTER display's cylinder: concentric mosaics, seed 002 eq. 1–4.
    #[default]
    Cylinder,
    /// The full sphere, equirectangular omni-directional stereo (Google ODS, Cycles' spherical
    /// stereo): 360° × 180° per eye.
    Equirect,
    /// VR180: the sphere's front half, equirectangular 180° × 180° per eye (W = H), the same eye
    /// model as `Equirect`; longitudes beyond ±90° fall outside the image.
    Vr180,
    /// The fulldome master: the sphere's eye rays drawn in an equidistant azimuthal (fisheye)
    /// image, W × W, the dome's axis at the centre.
    Fisheye,
    /// The stereo cubemap: the sphere's eye rays on the six 90° faces of a cube, one eye's
    /// image the 3×2 grid of YouTube's layout.
    Cubemap,
    /// CAVE walls: per wall and eye, the off-axis perspective image a tracked head's eye sees
    /// on a rectangle in the scene.
    Cave,
}

crate::choices!(PanoramaKind {
    Cylinder => ("cylinder", "The TWISTER display's cylinder: concentric mosaics, one image per eye"),
    Equirect => ("equirect", "The full sphere, equirectangular: 360° × 180° per eye"),
    Vr180 => ("vr180", "The sphere's front half: 180° × 180° per eye"),
    Fisheye => ("fisheye", "A dome master: an equidistant fisheye image, W × W"),
    Cubemap => ("cubemap", "A stereo cubemap: six 90° faces per eye in a 3×2 grid"),
    Cave => ("cave", "CAVE walls: an off-axis perspective image per wall and eye"),
});

impl PanoramaKind {
    /// Every panorama, in the registry's order.
    pub const ALL: &'static [PanoramaKind] = <PanoramaKind as crate::core::choice::Choice>::CHOICES;

    pub fn name(self) -> &'static str {
        crate::core::choice::Choice::name(self)
    }

    /// Its code in the WGSL projection uniform (`PANORAMA_CYLINDER`, `PANORAMA_EQUIRECT`): its
    /// index in the registry.
    pub const fn code(self) -> u32 {
        self as u32
    }
}
