//! Visual-field level of detail for polygon scenes (seed 001 §2.3, eq. 1–2).
//!
//! Each scene object (a glTF mesh instance, an OBJ object/group) gets a polygon budget from where
//! it falls in the visual field of the gaze (`visual_field`): the most central point of its
//! bounding sphere ([`nearest_to_gaze`]; an object around the viewer, a room, is central at full
//! detail whatever the gaze, so the level of detail never opens or empties it):
//!
//! ```text
//! central field:     P_m = P1 · (1 − D/D∞)
//! peripheral field:  P_m = P2 · (1 − D/D∞),  P2 = P1 − (P1 − P2')·(l − 30°)/(L − 30°)   (eq. 1)
//! outside:           P_m = P3
//! ```
//!
//! P1 is the object's own triangle count, P2' = `p2`·P1, P3 = `p3`·P1, D the distance from the
//! eye point to the object's centre (0 for an object around the viewer). The result is kept
//! within [P3, P1] (an object beyond D∞ would otherwise get a negative count).
//!
//! Simplified meshes come from meshoptimizer's quadric-error simplifier (the Garland–Heckbert QEM
//! the paper used), on the object's welded surface so that a closed object stays closed at every
//! level (`core::detail::simplify`): a chain of levels, each about `LEVEL_RATIO` (0.7) of the triangles of the one before, built once
//! per object down to P3 and cached. A frame draws, for each object, the coarsest level that still
//! has at least P_m triangles. The levels reuse the object's vertices, so UVs, normals and colours
//! stay as they were at the vertices the simplifier keeps.
//!
//! **The subdivision follows the level** (rule chosen here): an object's edge length L is divided
//! by its visual level (eq. 8) — full accuracy (L) in the central field, L/level in the peripheral
//! field, at most `MAX_EDGE_RELAXATION`·L — and outside the visual field its edges are not split
//! at all (the vertex method), since no one looks there.

use glam::{Mat4, Quat, Vec3};

use crate::core::detail::simplify::{simplify_chain, Welding};
use crate::core::detail::visual_field::{Field, Gaze};
use crate::core::scenes::scene::object_spheres;
use crate::core::scenes::scene::{Object, Scene};

pub use crate::core::detail::simplify::LEVEL_RATIO;
/// The most the peripheral field relaxes L (at the field's boundary).
pub const MAX_EDGE_RELAXATION: f32 = 4.0;
/// Objects with fewer triangles keep only their original: there is little to save, and the
/// simplifier would break their shape (a quad collapsed to one triangle loses half its area, a
/// box its faces).
pub const MIN_CHAIN_TRIANGLES: u32 = 64;
/// The factor on L that means "do not split" (outside the visual field).
pub const NO_SPLIT: f32 = 1e30;

/// The level-of-detail parameters (seed 001, table 2).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LodParams {
    /// P2' / P1: the peripheral field's smallest share of the triangles.
    pub p2: f32,
    /// P3 / P1: the share outside the visual field.
    pub p3: f32,
    /// D∞, metres: the central and peripheral budgets fall linearly with distance and would
    /// reach 0 at D∞; they are kept at least P3 (`budget`).
    pub d_inf: f32,
}

impl Default for LodParams {
    fn default() -> Self {
        LodParams::DEFAULT
    }
}

impl LodParams {
    pub const DEFAULT: LodParams = LodParams { p2: 0.3, p3: 0.05, d_inf: 100.0 };

    pub fn validate(&self) -> crate::error::Result<()> {
        use crate::error::Error;
        if !(self.p3 > 0.0 && self.p3 <= self.p2 && self.p2 <= 1.0) {
            return Err(Error::setting(
                "lod.p2/p3",
                format!("need 0 < P3 ≤ P2' ≤ 1, got P2' = {} and P3 = {}", self.p2, self.p3),
            ));
        }
        if !(self.d_inf > 0.0 && self.d_inf.is_finite()) {
            return Err(Error::setting(
                "lod.d_inf",
                format!("must be a positive distance in metres, got {}", self.d_inf),
            ));
        }
        Ok(())
    }

    /// P_m for an object of `p1` triangles whose centre is at `field` (with its eq. 8 level)
    /// and `distance` metres from the eye (eq. 1–2), kept within [P3, P1].
    pub fn budget(&self, p1: u32, field: Field, level: f32, distance: f32) -> f32 {
        let p1f = p1 as f32;
        let fade = 1.0 - distance / self.d_inf;
        let p = match field {
            Field::Central => p1f * fade,
            // P1 − (P1 − P2')·(l − 30°)/(L − 30°), and (l − 30°)/(L − 30°) = 1 − level.
            Field::Peripheral => (p1f - (p1f - self.p2 * p1f) * (1.0 - level)) * fade,
            Field::Outside => self.p3 * p1f,
        };
        p.clamp(self.p3 * p1f, p1f)
    }
}

/// The cached chain of simplified levels of every object: `levels[object][k]` is the index list
/// (three per triangle, into the scene's vertices) of level k; level 0 is the original.
pub struct LodChain {
    pub levels: Vec<Vec<Vec<u32>>>,
    /// `errors[object][k]`: how far level k may lie from the original, as a share of the
    /// object's extent (meshoptimizer's error of each simplification step, summed along the
    /// chain: an upper bound; 0 for level 0).
    pub errors: Vec<Vec<f32>>,
}

/// What a frame's selection chose for one object.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ObjectLod {
    pub field: Field,
    /// The visual level (eq. 8).
    pub level: f32,
    /// P_m and the triangles drawn (the chosen chain level's count).
    pub budget: f32,
    pub triangles: u32,
    /// The factor on L for its subdivision.
    pub edge_scale: f32,
}

/// A frame's selection: the index list to draw (objects in the scene's order), the objects'
/// ranges in it, and what was chosen for each.
#[derive(Clone)]
pub struct LodSelection {
    pub indices: Vec<u32>,
    pub objects: Vec<Object>,
    pub chosen: Vec<ObjectLod>,
}

impl LodChain {
    /// Simplifies every object down to `min_share` of its triangles, each level `LEVEL_RATIO` of the last.
    pub fn build(scene: &Scene, min_share: f32) -> LodChain {
        let welding = Welding::of(&scene.vertices);
        let (levels, errors) = scene
            .objects
            .iter()
            .map(|o| {
                let first = 3 * o.first_triangle as usize;
                let original = &scene.indices[first..first + 3 * o.triangle_count as usize];
                let floor = if o.triangle_count < MIN_CHAIN_TRIANGLES {
                    o.triangle_count as usize
                } else {
                    ((o.triangle_count as f32 * min_share).ceil() as usize).max(1)
                };
                simplify_chain(&scene.vertices, &welding, original, floor)
            })
            .unzip();
        LodChain { levels, errors }
    }

    /// Chooses each object's level for a gaze (in the viewer frame of `view`) and builds the
    /// frame's index list.
    pub fn select(&self, scene: &Scene, view: Mat4, gaze: &Gaze, params: &LodParams) -> LodSelection {
        let spheres = object_spheres(scene);
        let mut out = LodSelection { indices: Vec::new(), objects: Vec::new(), chosen: Vec::new() };
        for ((object, chain), (centre, radius)) in scene.objects.iter().zip(&self.levels).zip(spheres) {
            let c = view.transform_point3(centre);
            let (field, level, distance) = match nearest_to_gaze(gaze, c, radius) {
                // Around the viewer (a room): every gaze sees it, and it must stay closed.
                None => (Field::Central, 1.0, 0.0),
                Some(d) => {
                    let at = gaze.position(d);
                    (at.field(), at.level(), c.length())
                }
            };
            let budget = params.budget(object.triangle_count, field, level, distance);
            // The coarsest level that still has at least P_m triangles.
            let k = chain.iter().rposition(|l| (l.len() / 3) as f32 >= budget).unwrap_or(0);
            let first = (out.indices.len() / 3) as u32;
            out.indices.extend_from_slice(&chain[k]);
            let triangles = (chain[k].len() / 3) as u32;
            out.objects.push(Object { name: object.name.clone(), first_triangle: first, triangle_count: triangles });
            let edge_scale = match field {
                Field::Outside => NO_SPLIT,
                _ => (1.0 / level.max(1e-6)).min(MAX_EDGE_RELAXATION),
            };
            out.chosen.push(ObjectLod { field, level, budget, triangles, edge_scale });
        }
        out
    }
}

/// The direction of an object's bounding sphere (centre `c` in the viewer frame, `radius`)
/// nearest the gaze: its centre's direction turned towards the gaze by the sphere's angular
/// radius, or the gaze itself where the sphere reaches across it. None where the sphere holds
/// the viewer: the object surrounds the viewer (a room) and lies in every gaze's central field.
/// So an object's field is the most central one of any point of it, not of its centre (a room
/// whose centre is behind the gaze is not "outside").
pub fn nearest_to_gaze(gaze: &Gaze, c: Vec3, radius: f32) -> Option<Vec3> {
    let distance = c.length();
    if !(distance > radius) {
        return None;
    }
    let d = c / distance;
    let reach = (radius / distance).asin();
    let apart = d.dot(gaze.forward).clamp(-1.0, 1.0).acos();
    if apart <= reach {
        return Some(gaze.forward);
    }
    // Turn d towards the gaze in the plane of both (any plane holding d where they are opposite).
    let axis = d.cross(gaze.forward).try_normalize().unwrap_or_else(|| d.any_orthonormal_vector());
    Some(Quat::from_axis_angle(axis, reach) * d)
}

impl LodSelection {
    pub fn triangle_count(&self) -> u64 {
        self.chosen.iter().map(|c| c.triangles as u64).sum()
    }

    /// The scene as this selection draws it (same vertices, chosen triangles).
    pub fn scene(&self, scene: &Scene) -> Scene {
        Scene { indices: self.indices.clone(), objects: self.objects.clone(), ..scene.clone() }
    }

    pub fn edge_scales(&self) -> Vec<f32> {
        self.chosen.iter().map(|c| c.edge_scale).collect()
    }
}

/// `--lod-overlay`: tints each object's vertex colours by its level: green in the central field,
/// yellow (level 1) to red (level 0) across the peripheral field, dark red outside.
pub fn tint(scene: &mut Scene, selection: &LodSelection) {
    for v in &mut scene.vertices {
        let Some(c) = selection.chosen.get(v.object as usize) else { continue };
        let t = match c.field {
            Field::Central => [0.05, 0.6, 0.05],
            Field::Peripheral => [0.9, 0.15 + 0.65 * c.level, 0.02],
            Field::Outside => [0.3, 0.0, 0.0],
        };
        for (c, t) in v.color.iter_mut().zip(t) {
            *c = 0.35 * *c + 0.65 * t;
        }
    }
}

/// The visual field of a pixel of a panorama, from the viewer's centre: the pixel's direction is
/// `Projection::screen_direction` (on the cylinder (sin u, v/R_T, −cos u), the paper's vertical
/// model; the eyes' offset is left out, this is for looking at).
pub fn pixel_field(projection: &crate::core::panoramas::projection::Projection, gaze: &Gaze, x: f32, y: f32) -> Field {
    let (u, v) = projection.pixel_to_screen(x - 0.5, y - 0.5);
    gaze.position(projection.screen_direction(u, v)).field()
}

/// `--lod-overlay`: draws the central field's boundary (white) and the visual field's boundary
/// (orange) on an eye's image: the pixels on the inner side of each boundary.
pub fn draw_field_boundaries(
    img: &mut crate::core::frame::EyeImage,
    projection: &crate::core::panoramas::projection::Projection,
    gaze: &Gaze,
) {
    let (w, h) = (img.width, img.height);
    let fields: Vec<Field> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| pixel_field(projection, gaze, x as f32 + 0.5, y as f32 + 0.5))
        .collect();
    let at = |x: u32, y: u32| fields[(y * w + x) as usize];
    for y in 0..h {
        for x in 0..w {
            let here = at(x, y);
            let others = [(x + 1) % w, (x + w - 1) % w]
                .map(|nx| at(nx, y))
                .into_iter()
                .chain([y.checked_sub(1), (y + 1 < h).then_some(y + 1)].into_iter().flatten().map(|ny| at(x, ny)));
            let mut colour = None;
            for o in others {
                if o != here {
                    // The inner side of each boundary is painted.
                    colour = match (here, o) {
                        (Field::Central, _) => Some([255, 255, 255, 255]),
                        (Field::Peripheral, Field::Outside) => Some([255, 140, 0, 255]),
                        _ => colour,
                    };
                }
            }
            if let Some(c) = colour {
                let i = 4 * (y * w + x) as usize;
                img.rgba[i..i + 4].copy_from_slice(&c);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::scenes::builtin::sphere_scene;
    use glam::Vec3;

    #[test]
    fn budgets_follow_eq_1_and_2() {
        let p = LodParams { p2: 0.3, p3: 0.05, d_inf: 100.0 };
        assert_eq!(p.budget(1000, Field::Central, 1.0, 0.0), 1000.0);
        assert!((p.budget(1000, Field::Central, 1.0, 10.0) - 900.0).abs() < 1e-3);
        // Peripheral at the central edge (level 1) is P1, at the boundary (level 0) P2'.
        assert!((p.budget(1000, Field::Peripheral, 1.0, 0.0) - 1000.0).abs() < 1e-3);
        assert!((p.budget(1000, Field::Peripheral, 0.0, 0.0) - 300.0).abs() < 1e-3);
        assert!((p.budget(1000, Field::Peripheral, 0.5, 50.0) - 325.0).abs() < 1e-3);
        assert_eq!(p.budget(1000, Field::Outside, 0.0, 1.0), 50.0);
        assert_eq!(p.budget(1000, Field::Central, 1.0, 500.0), 50.0, "beyond D∞: kept at P3");
    }

    proptest::proptest! {
        // A fixed list of cases (PROPTEST_RNG_SEED changes it).
        #![proptest_config(proptest::test_runner::Config {
            rng_seed: match proptest::test_runner::Config::default().rng_seed {
                proptest::test_runner::RngSeed::Random => proptest::test_runner::RngSeed::Fixed(58),
                fixed => fixed,
            },
            ..proptest::test_runner::Config::with_cases(64)
        })]

        /// A closed room around the viewer (its centre anywhere within it, often behind the
        /// gaze) is drawn whole at full detail, whatever the gaze; an object that reaches across
        /// the gaze is central.
        #[test]
        fn a_room_around_the_viewer_is_central_at_any_gaze(
            yaw in -180.0f32..180.0,
            pitch in -89.0f32..89.0,
            offset in proptest::array::uniform3(-0.9f32..0.9),
            size in 1.0f32..30.0,
        ) {
            let mut scene = Scene::new("room");
            let room = crate::core::scenes::shapes::ClosedMesh::grid_box(4).placed(Vec3::from(offset) * size, size);
            room.add_to(&mut scene, [1.0; 4]);
            // A long wall 2 m in front of the gaze, its centre 40° to the side of it.
            let gaze = Gaze::new(yaw, pitch);
            let side = gaze.forward.cross(gaze.up);
            let wall = sphere_scene(400, 2.0 * gaze.forward + 2.0 * 40f32.to_radians().tan() * side, 1.8, "wall");
            scene.add_mesh("wall", &wall.vertices, &wall.indices);
            let chain = LodChain::build(&scene, 0.05);
            let sel = chain.select(&scene, Mat4::IDENTITY, &gaze, &LodParams::default());
            for (o, chosen) in sel.chosen.iter().enumerate() {
                proptest::prop_assert_eq!(chosen.field, Field::Central, "object {}", o);
                proptest::prop_assert_eq!(chosen.edge_scale, 1.0);
            }
            proptest::prop_assert_eq!(sel.chosen[0].triangles, scene.objects[0].triangle_count);
        }
    }

    #[test]
    fn objects_get_the_coarsest_level_meeting_their_budget() {
        // Four spheres 3 m away: ahead, 60° left, 90° right, behind.
        let mut scene = Scene::new("four");
        for (k, deg) in [0.0f32, 60.0, -90.0, 180.0].into_iter().enumerate() {
            let (s, c) = deg.to_radians().sin_cos();
            let one = sphere_scene(2000, Vec3::new(-3.0 * s, 0.0, -3.0 * c), 0.5, "sphere");
            scene.add_mesh(format!("sphere {k}"), &one.vertices, &one.indices);
        }
        let chain = LodChain::build(&scene, 0.05);
        // A small object, such as a flat quad, has no coarser level.
        let mut quad = Scene::new("quad");
        let corner =
            |x: f32, z: f32| crate::core::scenes::scene::SceneVertex { position: [x, 0.0, z], ..Default::default() };
        quad.add_mesh(
            "quad",
            &[corner(0.0, 0.0), corner(0.0, 1.0), corner(1.0, 1.0), corner(1.0, 0.0)],
            &[0, 1, 2, 0, 2, 3],
        );
        assert_eq!(LodChain::build(&quad, 0.05).levels[0].len(), 1);
        for levels in &chain.levels {
            assert!(levels.len() >= 4, "{} levels", levels.len());
            for w in levels.windows(2) {
                assert!(w[1].len() < w[0].len());
            }
        }
        let p = LodParams::default();
        let sel = chain.select(&scene, Mat4::IDENTITY, &Gaze::default(), &p);
        let fields: Vec<Field> = sel.chosen.iter().map(|c| c.field).collect();
        assert_eq!(fields, [Field::Central, Field::Peripheral, Field::Peripheral, Field::Outside]);
        for (o, (c, levels)) in sel.chosen.iter().zip(&chain.levels).enumerate() {
            let counts: Vec<f32> = levels.iter().map(|l| (l.len() / 3) as f32).collect();
            assert!(c.triangles as f32 >= c.budget || c.triangles as f32 == *counts.last().unwrap(), "{o}: {c:?}");
            // No coarser level would do.
            let k = counts.iter().position(|&n| n == c.triangles as f32).unwrap();
            assert!(k + 1 == counts.len() || counts[k + 1] < c.budget, "{o}: {c:?} {counts:?}");
        }
        assert_eq!(sel.chosen[0].triangles, scene.objects[0].triangle_count, "central: the original (1 − 3/100 ≈ 1)");
        assert!(sel.chosen[3].triangles < sel.chosen[1].triangles);
        assert_eq!(sel.chosen[0].edge_scale, 1.0);
        assert!(sel.chosen[1].edge_scale > 1.0 && sel.chosen[1].edge_scale <= MAX_EDGE_RELAXATION);
        assert_eq!(sel.chosen[3].edge_scale, NO_SPLIT);
        // The frame's index list holds exactly the chosen levels, object by object.
        assert_eq!(sel.indices.len() as u64, 3 * sel.triangle_count());
        let drawn = sel.scene(&scene);
        drawn.validate().unwrap();
        for (o, obj) in drawn.objects.iter().enumerate() {
            let r = 3 * obj.first_triangle as usize..3 * (obj.first_triangle + obj.triangle_count) as usize;
            assert!(drawn.indices[r].iter().all(|&i| drawn.vertices[i as usize].object == o as u32));
        }
    }
}
