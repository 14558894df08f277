//! The subdivision's promises checked on its CPU twin against the input mesh itself (the
//! oracle: brute-force geometry, no second subdivision):
//! - **watertight**: every output edge (by the exact bits of its two end points) is used by an
//!   even number of output triangles (two; four inside two copies of a face, which a simplified
//!   level of detail may hold), except where the stage leaves nothing to draw by design: the
//!   square around the axis (no eye sees it), wholly above or below the image's rows or in the
//!   fisheye's antipode cone (`Subdivider::off_screen_vertically`), within `SEAM_MARGIN` of the
//!   image's side or beyond it (VR180's back: `PiecePlan::copy_shows` draws no copy there, and no
//!   sample lies there), along an input edge used other than twice (open, or non-manifold), or
//!   between slivers narrower than the coordinates' precision: no crack, no T-junction;
//! - **drawn together**: every copy of a node is drawn off its projection by the same offset;
//! - **nothing visible removed, nothing added**: every output triangle of a sample of input
//!   triangles lies on its input triangle and outside the square around the axis, and random
//!   points of it that some eye can see are covered by its output.

use std::collections::HashMap;

use glam::Vec3;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::core::panoramas::projection::{azimuth, horizontal_radius, wrap_angle, Eye};
use crate::core::scenes::scene::SceneVertex;
use crate::cpu::subdivide::{FrameCuts, Subdivider};
use crate::encoding::constants::SEAM_MARGIN;
use crate::encoding::types::{DrawVertex, SubdivideParams};

type Key = [u32; 3];

fn key(p: Vec3) -> Key {
    p.to_array().map(f32::to_bits)
}

fn edge_key(a: Vec3, b: Vec3) -> (Key, Key) {
    let (ka, kb) = (key(a), key(b));
    if ka < kb {
        (ka, kb)
    } else {
        (kb, ka)
    }
}

/// One subdivision checked: the scene's vertices and indices, the stage's parameters and each
/// object's factor on L.
pub struct Topology<'a> {
    pub vertices: &'a [SceneVertex],
    pub indices: &'a [u32],
    pub params: SubdivideParams,
    pub edge_scale: &'a [f32],
}

impl Topology<'_> {
    /// Runs the twin on the whole scene and checks both promises (the second on `sampled`
    /// input triangles drawn from `seed`); the number of distinct output triangles, or the first
    /// broken promise in one line.
    pub fn check(&self, sampled: usize, seed: u64) -> Result<usize, String> {
        let sd = Subdivider::with_edge_scale(&self.params, self.edge_scale);
        let out = sd.run(self.vertices, self.indices);
        let cuts = sd.active_cuts(self.vertices, self.indices);
        if cuts.axis != out.cuts {
            return Err(format!("cuts: the frame's {:#x}, the run's {:#x}", cuts.axis, out.cuts));
        }
        let corners: Vec<[Vec3; 3]> =
            (0..self.indices.len() / 3).map(|t| sd.positions(self.vertices, self.indices, t)).collect();
        let tol = 4e-6 * corners.iter().flatten().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        let originals = distinct_triangles(&out.vertices);
        self.watertight(&sd, &corners, &originals, tol)?;
        same_offsets(&out.vertices)?;
        let mut rng = StdRng::seed_from_u64(seed);
        for _ in 0..sampled.min(corners.len()) {
            let t = rng.random_range(0..corners.len());
            self.whole(&sd, &cuts, t, corners[t], tol, &mut rng)?;
        }
        Ok(originals.len())
    }

    /// Every output edge is shared by exactly two triangles (its `originals`, seam copies
    /// aside), except where the module doc says.
    fn watertight(
        &self,
        sd: &Subdivider,
        corners: &[[Vec3; 3]],
        originals: &[&[DrawVertex]],
        tol: f32,
    ) -> Result<(), String> {
        let rho = sd.axis_clearance();
        // Input edges used other than twice (an open or non-manifold input) may stay open.
        let mut input_edges: HashMap<(Key, Key), u32> = HashMap::new();
        for c in corners {
            for e in 0..3 {
                *input_edges.entry(edge_key(c[e], c[(e + 1) % 3])).or_default() += 1;
            }
        }
        let open_input: Vec<(Vec3, Vec3)> = input_edges
            .iter()
            .filter(|(_, &n)| n != 2)
            .map(|((a, b), _)| (Vec3::from(a.map(f32::from_bits)), Vec3::from(b.map(f32::from_bits))))
            .collect();
        let on_open_input = |a: Vec3, b: Vec3| {
            open_input.iter().any(|&(p, q)| {
                let d = q - p;
                [a, b].iter().all(|&x| {
                    (x - p).cross(d).length() <= tol * d.length() && (x - p).dot(d) >= -tol && (x - q).dot(-d) >= -tol
                })
            })
        };
        let on_square = |p: Vec3| (p.x.abs() + p.z.abs() - rho).abs() <= tol + 1e-3 * rho;

        let mut edges: HashMap<(Key, Key), u32> = HashMap::new();
        for t in originals {
            for e in 0..3 {
                *edges.entry(edge_key(Vec3::from(t[e].position), Vec3::from(t[(e + 1) % 3].position))).or_default() +=
                    1;
            }
        }
        // Slivers: triangles narrower than the coordinates' precision (beside the square around
        // the axis, a part can be ρ wide and metres long; its lattice nodes may round together).
        let sliver = |t: &[DrawVertex]| {
            let p = [0, 1, 2].map(|i| Vec3::from(t[i].position));
            let longest = (p[1] - p[0]).length().max((p[2] - p[1]).length()).max((p[0] - p[2]).length());
            (p[1] - p[0]).cross(p[2] - p[0]).length() <= 2.0 * tol * longest
        };
        let mut at_edge: HashMap<(Key, Key), bool> = HashMap::new();
        for t in originals {
            for e in 0..3 {
                let k = edge_key(Vec3::from(t[e].position), Vec3::from(t[(e + 1) % 3].position));
                *at_edge.entry(k).or_insert(true) &= sliver(t);
            }
        }
        for (edge, n) in &edges {
            // Used an even number of times: closed there (twice, or four times inside two
            // copies of one face, which a simplified level of detail can hold).
            if n % 2 == 0 || at_edge[edge] {
                continue;
            }
            let (a, b) = (Vec3::from(edge.0.map(f32::from_bits)), Vec3::from(edge.1.map(f32::from_bits)));
            // Along an input edge used other than twice, any count may stay.
            let allowed = on_open_input(a, b)
                || (*n == 1
                    && ((on_square(a) && on_square(b))
                        || sd.off_screen_vertically([a, b, a])
                        || edge_beyond_image_side(sd, a, b)));
            if !allowed {
                return Err(format!("edge {a} – {b} used by {n} triangles (crack or T-junction)"));
            }
        }
        Ok(())
    }

    /// Input triangle `t` (corners `corner` in the viewer frame, snapped), subdivided alone with
    /// the frame's cuts: its output lies on its plane, inside it and outside the square around
    /// the axis, and covers 40 random points of it that are on screen.
    fn whole(
        &self,
        sd: &Subdivider,
        cuts: &FrameCuts,
        t: usize,
        corner: [Vec3; 3],
        tol: f32,
        rng: &mut StdRng,
    ) -> Result<(), String> {
        let rho = sd.axis_clearance();
        let one = SubdivideParams { first_triangle: t as u32, triangle_count: 1, ..self.params };
        let out = Subdivider::with_edge_scale(&one, self.edge_scale).run_with_cuts(self.vertices, self.indices, cuts);
        let normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
        if normal.length() == 0.0 {
            return Ok(());
        }
        let bary_of = |p: Vec3| -> Vec3 {
            let area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).dot(normal) / normal.length_squared();
            Vec3::new(area(p, corner[1], corner[2]), area(corner[0], p, corner[2]), area(corner[0], corner[1], p))
        };
        let mine = distinct_triangles(&out.vertices);
        for v in mine.iter().flat_map(|t| t.iter()) {
            let p = Vec3::from(v.position);
            let off_plane = (p - corner[0]).dot(normal.normalize()).abs();
            if off_plane > tol {
                return Err(format!("triangle {t}: output point {p} is {off_plane} off its plane"));
            }
            if bary_of(p).min_element() < -1e-4 {
                return Err(format!("triangle {t}: output point {p} outside it"));
            }
            if p.x.abs() + p.z.abs() < rho - tol {
                return Err(format!("triangle {t}: output point {p} inside the square around the axis"));
            }
        }
        let k = sd.vertical_limit();
        for _ in 0..40 {
            let (a, b): (f32, f32) = (rng.random(), rng.random());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let p = corner[0] + a * (corner[1] - corner[0]) + b * (corner[2] - corner[0]);
            let r = horizontal_radius(p);
            // Clearly outside the square and clearly on screen (margins for the sub-triangles
            // culled whole: those lie wholly beyond the image, and so does such a point then).
            let off_screen = p.y.abs() > 0.99 * k * r
                || sd.around_dome_antipode([p; 3])
                || beyond_image_side(sd, p)
                || drawn_beyond_image_side(sd, corner, a, b)
                || (sd.projection().model().drawn_as_pinhole() && !sd.projection().cave_sees(p));
            if p.x.abs() + p.z.abs() < rho * 1.01 + 2.0 * tol || off_screen {
                continue;
            }
            let w = bary_of(p);
            let covered = mine.iter().any(|t| {
                let q = [0, 1, 2].map(|i| bary_of(Vec3::from(t[i].position)));
                let d = (q[1] - q[0]).truncate().perp_dot((q[2] - q[0]).truncate());
                if d == 0.0 {
                    return false;
                }
                let s = (w - q[0]).truncate().perp_dot((q[2] - q[0]).truncate()) / d;
                let u = (q[1] - q[0]).truncate().perp_dot((w - q[0]).truncate()) / d;
                s >= -1e-4 && u >= -1e-4 && s + u <= 1.0 + 1e-4
            });
            if !covered {
                return Err(format!("visible point {p} of input triangle {t} is not covered by its output"));
            }
        }
        Ok(())
    }
}

/// Every copy of a node (the same position, in any triangle) is drawn off its projection by
/// the same screen offset (the equirectangular panoramas under the error split): else the
/// triangles that share it are drawn apart there, a crack.
fn same_offsets(vertices: &[DrawVertex]) -> Result<(), String> {
    let mut offsets: HashMap<Key, [f32; 4]> = HashMap::new();
    for v in vertices {
        let first = *offsets.entry(key(Vec3::from(v.position))).or_insert(v.offsets);
        let apart = first.iter().zip(&v.offsets).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        if apart > 1e-3 {
            return Err(format!(
                "node {:?} drawn off its projection by {:?} in one triangle and {:?} in another ({apart} px apart: a crack)",
                v.position, first, v.offsets
            ));
        }
    }
    Ok(())
}

/// How far from the image's centre column, in longitude, a point's u lies beyond its left or
/// right side, within `SEAM_MARGIN` of it: a triangle there covers no sample (the nearest lies
/// 1/16 px in) and `lattice_triangles` draws no copy of it. None on the images whose x is no
/// longitude.
fn side_limit(sd: &Subdivider) -> Option<f32> {
    let seamless = sd.projection().model().turn_share().is_none();
    (!seamless).then(|| sd.image_half_span() - 1.01 * SEAM_MARGIN)
}

/// Whether `beyond(u, limit)` holds in both eyes, u the eye's longitude of each point of `p`.
fn beyond_in_both_eyes<const N: usize>(sd: &Subdivider, p: [Vec3; N], beyond: impl Fn([f32; N], f32) -> bool) -> bool {
    let Some(limit) = side_limit(sd) else { return false };
    [Eye::Left, Eye::Right]
        .into_iter()
        .all(|eye| beyond(p.map(|q| sd.projection().project_with_azimuth(q, azimuth(q), eye).u), limit))
}

/// Whether a point lies within `SEAM_MARGIN` of the image's left or right side, or beyond them
/// (VR180's back), in every eye ([`side_limit`]).
fn beyond_image_side(sd: &Subdivider, p: Vec3) -> bool {
    beyond_in_both_eyes(sd, [p], |[u], limit| wrap_angle(u).abs() >= limit)
}

/// Whether the point at (a, b) of a triangle (corners `corner`) drawn straight between its
/// corners' projections lies within `SEAM_MARGIN` of the image's side or beyond it in every
/// eye: `vertex` draws the triangle so, and drops it when its corners lie beyond (the true
/// image of its middle may reach a pixel in).
fn drawn_beyond_image_side(sd: &Subdivider, corner: [Vec3; 3], a: f32, b: f32) -> bool {
    beyond_in_both_eyes(sd, corner, |u, limit| {
        let u0 = wrap_angle(u[0]);
        (u0 + a * wrap_angle(u[1] - u0) + b * wrap_angle(u[2] - u0)).abs() >= limit
    })
}

/// Whether an output edge is drawn wholly within `SEAM_MARGIN` of the image's left or right
/// side or beyond it, in every eye: it is drawn straight between its ends' projections (x
/// unwrapped from one end to the other, as the raster stage unwraps a triangle), so both ends
/// beyond the same side put all of it there, whatever the curve between them would show (the
/// vertex method draws a wall's sliver beyond VR180's side that the true projection of its
/// middle brings a pixel inside).
fn edge_beyond_image_side(sd: &Subdivider, a: Vec3, b: Vec3) -> bool {
    beyond_in_both_eyes(sd, [a, b], |[ua, ub], limit| {
        let ua = wrap_angle(ua);
        let ub = ua + wrap_angle(ub - ua);
        (ua >= limit && ub >= limit) || (ua <= -limit && ub <= -limit)
    })
}

/// The output triangles, each once: a seam copy (the same corners, another reference azimuth)
/// left out. Which copy shows varies: a copy wholly beyond the image's columns is not drawn.
fn distinct_triangles(vertices: &[DrawVertex]) -> Vec<&[DrawVertex]> {
    let mut seen = std::collections::HashSet::new();
    vertices
        .chunks(3)
        .filter(|t| seen.insert(t.iter().map(|v| v.position.map(f32::to_bits)).collect::<Vec<_>>()))
        .collect()
}
