//! The registry: every panorama's type ([`PANORAMAS`], in [`PanoramaKind`]'s order), how a kind
//! finds its type, and the [`Projection`] of a kind.

use crate::core::panoramas::panorama::{EyeModel, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::Projection;
use crate::core::panoramas::{cave, cubemap, cylinder, equirect, fisheye, vr180};

/// The registry: every panorama's type, in [`PanoramaKind`]'s order.
pub static PANORAMAS: [&dyn Panorama; 6] =
    [&cylinder::Cylinder, &equirect::Equirect, &vr180::Vr180, &fisheye::Fisheye, &cubemap::Cubemap, &cave::Cave];

impl PanoramaKind {
    /// Its type, from the registry.
    pub fn model(self) -> &'static dyn Panorama {
        PANORAMAS[self as usize]
    }

    /// Whether the panorama draws the full sphere's eye rays (`core::panoramas::sphere`).
    pub fn is_sphere(self) -> bool {
        self.model().eye_model() == EyeModel::Sphere
    }

    /// Whether the image is equirectangular (the sphere, VR180): what GPano and `sv3d`/`equi`
    /// describe.
    pub fn is_equirectangular(self) -> bool {
        self.is_sphere() && self.model().image_map() == ImageMap::Linear
    }

    /// The share of a full turn of azimuth that the image's width spans: 1, or ½ for VR180
    /// (1 where the image has no seam).
    pub fn turn_share(self) -> f32 {
        self.model().turn_share().unwrap_or(1.0)
    }

    pub fn player_tag(self) -> Option<&'static str> {
        self.model().player_tag()
    }

    /// Whether the image's width is the whole turn (its left and right edges meet).
    pub fn wraps(self) -> bool {
        self.model().turn_share() == Some(1.0)
    }

    /// The panorama of a code; None for a code no panorama has.
    pub fn from_code(code: u32) -> Option<PanoramaKind> {
        PANORAMAS.get(code as usize).map(|m| m.kind())
    }
}

impl Projection {
    /// The panorama `kind`, `width` pixels wide, of its default height
    /// ([`Panorama::default_size`]); parallel rays, Blender's pole merge.
    pub fn of(kind: PanoramaKind, width: u32) -> Projection {
        let [width, height] = kind.model().default_size(width);
        Projection { panorama: kind, width, height, ..Projection::default() }
    }

    /// Its panorama's type.
    pub fn model(&self) -> &'static dyn Panorama {
        self.panorama.model()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_holds_each_kind_at_its_code() {
        for (code, model) in PANORAMAS.iter().enumerate() {
            let kind = model.kind();
            assert_eq!((kind.code(), kind.model().wgsl_name()), (code as u32, model.wgsl_name()));
            assert_eq!(PanoramaKind::from_code(code as u32), Some(kind));
        }
        let all = <PanoramaKind as crate::core::choice::Choice>::CHOICES;
        assert_eq!(all.len(), PANORAMAS.len(), "every kind has a type in the registry");
        assert!(all.iter().enumerate().all(|(i, k)| k.code() == i as u32), "the kinds' order is the registry's");
    }
}
