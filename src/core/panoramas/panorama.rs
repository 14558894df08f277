//! The panoramas twister renders (`--panorama`): which image each is, its code in the WGSL
//! projection uniform and the facts about its image the rest of the pipeline asks (the sphere's
//! eye model or the cylinder's, the azimuth its width spans, the name players detect). The maps
//! themselves are `core::panoramas::projection` (the cylinder), `core::panoramas::sphere`, `core::panoramas::fisheye`,
//! `core::panoramas::cubemap`, `core::panoramas::cave`.

/// The panoramas twister renders (`--panorama`).
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
    /// image, W × W, the dome's axis at the centre (`core::panoramas::fisheye`).
    Fisheye,
    /// The stereo cubemap: the sphere's eye rays on the six 90° faces of a cube, one eye's
    /// image the 3×2 grid of YouTube's layout (`core::panoramas::cubemap`).
    Cubemap,
    /// CAVE walls: per wall and eye, the off-axis perspective image a tracked head's eye sees
    /// on a rectangle in the scene (`core::panoramas::cave`).
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
    pub const ALL: [PanoramaKind; 6] = [
        PanoramaKind::Cylinder,
        PanoramaKind::Equirect,
        PanoramaKind::Vr180,
        PanoramaKind::Fisheye,
        PanoramaKind::Cubemap,
        PanoramaKind::Cave,
    ];

    pub fn name(self) -> &'static str {
        match self {
            PanoramaKind::Cylinder => "cylinder",
            PanoramaKind::Equirect => "equirect",
            PanoramaKind::Vr180 => "vr180",
            PanoramaKind::Fisheye => "fisheye",
            PanoramaKind::Cubemap => "cubemap",
            PanoramaKind::Cave => "cave",
        }
    }

    /// Whether the panorama is (part of) the full sphere's equirectangular ODS: longitude u,
    /// latitude v, the eye model of `core::panoramas::sphere`.
    pub const fn is_sphere(self) -> bool {
        matches!(self, PanoramaKind::Equirect | PanoramaKind::Vr180 | PanoramaKind::Fisheye | PanoramaKind::Cubemap)
    }

    /// Whether the image is equirectangular (the sphere, VR180): what GPano and `sv3d`/`equi`
    /// describe.
    pub const fn is_equirectangular(self) -> bool {
        matches!(self, PanoramaKind::Equirect | PanoramaKind::Vr180)
    }

    /// The share of a full turn of azimuth that the image's width spans: 1, or ½ for VR180.
    pub const fn turn_share(self) -> f32 {
        match self {
            PanoramaKind::Vr180 => 0.5,
            _ => 1.0,
        }
    }

    /// The tag VR players detect in a file name (`_360`, `_180`); None for the cylinder, which is
    /// no player format.
    pub const fn player_tag(self) -> Option<&'static str> {
        match self {
            PanoramaKind::Cylinder => None,
            PanoramaKind::Equirect => Some("360"),
            PanoramaKind::Vr180 => Some("180"),
            PanoramaKind::Fisheye => Some("fisheye"),
            PanoramaKind::Cubemap => Some("cubemap"),
            PanoramaKind::Cave => None,
        }
    }

    /// Whether the image's width is the whole turn (its left and right edges meet).
    pub const fn wraps(self) -> bool {
        !matches!(self, PanoramaKind::Vr180 | PanoramaKind::Fisheye | PanoramaKind::Cubemap | PanoramaKind::Cave)
    }

    /// Its code in the WGSL projection uniform (`PANORAMA_CYLINDER`, `PANORAMA_EQUIRECT`).
    pub const fn code(self) -> u32 {
        match self {
            PanoramaKind::Cylinder => 0,
            PanoramaKind::Equirect => 1,
            PanoramaKind::Vr180 => 2,
            PanoramaKind::Fisheye => 3,
            PanoramaKind::Cubemap => 4,
            PanoramaKind::Cave => 5,
        }
    }

    /// The panorama of a code; None for a code no panorama has.
    pub fn from_code(code: u32) -> Option<PanoramaKind> {
        PanoramaKind::ALL.into_iter().find(|p| p.code() == code)
    }
}
