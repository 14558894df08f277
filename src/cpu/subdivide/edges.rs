//! CPU twin of `shaders/shared/subdivide_edges.wgsl`: eq. 5's edge counts (the projected
//! length, or the error split's bend), the nodes on an edge from its canonically ordered ends, a
//! triangle's loading and its vertical culling, and a part's plan (see the module doc of
//! `cpu::subdivide`).

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::spacing::Spacing;
use super::{snap_to_cut_planes, Node, PartSplit, Subdivider, Triangle};
use crate::core::panoramas::panorama::{EyeModel, ImageMap};
use crate::core::panoramas::projection::{azimuth, horizontal_radius, Eye, Vertical};
use crate::core::scenes::scene::{unpack_tangent, SceneVertex, SINGLE_SIDED};
use crate::core::settings::SplitRule;
use crate::encoding::constants::{
    AZIMUTH_CHORD_RESIDUAL, AZIMUTH_RESIDUAL_ERROR, BACK_FACE_MARGIN, EDGE_SAMPLES, ERROR_SPLIT_LENGTH,
    MAX_EDGE_DIVISIONS, MAX_MACRO_LEVEL, MAX_STRETCH, PIECE_DIVISIONS, ROW_DIAGONAL_ERROR,
};

pub(super) fn lex_less(a: Vec3, b: Vec3) -> bool {
    a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)))
}

/// The point j/n of the way from `a` to `b` (spaced by `spacing`), computed from the canonically
/// ordered pair so that both triangles sharing the edge get the same bits; the ends are exact.
pub(super) fn edge_point(a: Node, b: Node, j: u32, n: u32, spacing: Spacing) -> Node {
    let (lo, hi, jj) = if lex_less(b.position, a.position) { (b, a, n - j) } else { (a, b, j) };
    if jj == 0 {
        return lo;
    }
    if jj == n {
        return hi;
    }
    spacing.mix(lo, hi, jj as f32 / n as f32)
}

/// What [`Subdivider::edge_profile`] measures of an edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeProfile {
    pub length_px: f32,
    pub bend_px: f32,
    pub ring: bool,
    /// Under azimuth spacing, how far the drawing between the ends strays from the point of
    /// its step of azimuth (`AZIMUTH_CHORD_RESIDUAL`·D³ radians, D the sweep, × the fastest
    /// pixels per radian sampled); n parts leave 1/n³ of it. 0 otherwise.
    pub residual_px: f32,
    /// Each eye's largest second difference (left, right; y up): where nodes are drawn off
    /// their projections, the line's offset (`cpu::subdivide::offsets`).
    pub bend_vec: [Vec2; 2],
}

impl EdgeProfile {
    /// Parts that keep the drawing's residual within `AZIMUTH_RESIDUAL_ERROR`·τ: the fewest n
    /// with n³ at least residual / that (the cube root's guess corrected by products, which
    /// round alike on the GPU, whose `pow` does not).
    pub(super) fn parts_for_residual(&self, max_error_px: f32) -> f32 {
        let x = self.residual_px / (AZIMUTH_RESIDUAL_ERROR * max_error_px);
        if x <= 1.0 {
            return 1.0;
        }
        let n = x.cbrt().ceil();
        if (n - 1.0) * (n - 1.0) * (n - 1.0) >= x {
            n - 1.0
        } else if n * n * n < x {
            n + 1.0
        } else {
            n
        }
    }

    /// Whether the edge drawn in one part strays at most `share`·τ from its bend and within
    /// the residual's share from its step of azimuth, away from the eye circle (the quick
    /// profile's test of an edge or a strip's base).
    pub(super) fn straight(&self, share: f32, max_error_px: f32) -> bool {
        !self.ring
            && parts_for_bend(self.bend_px, 2, share * max_error_px) <= 1.0
            && self.parts_for_residual(max_error_px) <= 1.0
    }
}

/// A triangle's L and τ (see [`Subdivider::limits`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    pub(super) edge_px: f32,
    pub(super) max_error_px: f32,
}

/// Parts an edge needs so that its chord error, about bend·S²/(8n²) for n parts (see
/// [`Subdivider::edge_profile`]), is at most τ: ceil(S·√(bend / 8τ)) (not rounded to an integer
/// count yet; NaN stays NaN).
pub(super) fn parts_for_bend(bend_px: f32, segments: u32, max_error_px: f32) -> f32 {
    (segments as f32 * (bend_px / (8.0 * max_error_px)).sqrt()).ceil()
}

impl Subdivider<'_> {
    /// How the frame spaces nodes along a segment: by azimuth under the error split.
    pub(super) fn spacing(&self) -> Spacing {
        Spacing::of(self.params)
    }

    /// L and τ for a triangle of `object`: the level of detail scales L by its factor s, and τ by
    /// s² (an edge's error grows as the square of its parts' length).
    pub(super) fn limits(&self, object: u32) -> Limits {
        let s = self.edge_scale.get(object as usize).copied().unwrap_or(1.0);
        Limits { edge_px: self.params.edge_px * s, max_error_px: self.params.max_error_px * (s * s) }
    }

    /// Image position (x, y) in pixels of a viewer-frame point for one eye sign, x not wrapped.
    pub(super) fn pixel(&self, p: Vec3, eye_sign: f32) -> Vec2 {
        let eye = if eye_sign > 0.0 { Eye::Right } else { Eye::Left };
        let q = self.projection.project_with_azimuth(p, azimuth(p), eye);
        let proj = &self.projection;
        if proj.model().image_map() == ImageMap::Fisheye {
            // Its own image, centred (no seam: x never wraps).
            let [x, y] = proj.fisheye_pixel(q.u, q.v);
            return Vec2::new(x - 0.5 * proj.width as f32, y - 0.5 * proj.height as f32);
        }
        Vec2::new(q.u * proj.pixels_per_radian(), q.v * proj.pixels_per_v())
    }

    /// What the split rules read of the straight edge ab, projected and sampled as a polyline
    /// through `segments` + 1 points (both eyes, x unwrapped across the seam), in the edge's
    /// canonical order:
    /// - `length_px`, by which eq. 5 splits it: the polyline's length l (the larger of the two
    ///   eyes) or, if larger, `segments` × its longest segment / `MAX_STRETCH` (/ 1 in the paper
    ///   model where the edge comes within 2·d_e of the axis: α ∝ √(r − d_e) bends it sharply):
    ///   an edge the projection stretches unevenly gets equal parts short enough where it is
    ///   stretched most. Heights are clamped to ±1.5 image heights from the middle row, so
    ///   off-screen parts count little, and segments beyond the clamp at both ends (on one side)
    ///   count nothing.
    /// - `bend_px`, by which the error split splits it: the largest second difference
    ///   |q(k+1) − 2 q(k) + q(k−1)| of the sampled points (both eyes; triples with a point beyond the
    ///   height clamp are skipped). A straight edge drawn with its nodes at the projected places
    ///   is wrong between the nodes by about |q''|·(t/n)²/8 for n parts (q'' the second derivative
    ///   along the edge's parameter t, whose sampled estimate is bend·S²): the chord's error,
    ///   across and along the curve (the drawn point j/n of the way is not where the point j/n
    ///   of the way along the 3-D edge projects).
    /// - `ring`: the edge comes within twice the eye offset at its altitude of the axis where the
    ///   panorama shows the eye circle (d_e; on the sphere the pole merge fades the offset, so
    ///   an edge near the axis but far above or below the eyes, as a floor under the viewer, is
    ///   no ring: there the eyes meet and the longitude is the azimuth).
    /// - `residual_px`: see [`EdgeProfile`].
    ///
    /// The points are spaced as the frame spaces nodes ([`Spacing`]), so that under the error
    /// split the second differences measure the image's curvature against azimuth, which is
    /// what its drawing with w = r leaves (`cpu::subdivide::spacing`).
    pub fn edge_profile(&self, a: Vec3, b: Vec3, segments: u32) -> EdgeProfile {
        let (lo, hi) = if lex_less(b, a) { (b, a) } else { (a, b) };
        if self.params.pinhole_faces != 0 {
            return self.pinhole_profile(lo, hi, segments);
        }
        let spacer = self.spacing().spacer(lo, hi);
        let clamp_v = 1.5 * self.projection.height as f32;
        let width = self.projection.turn_px(); // a full turn in pixels: x wraps at it
        let (mut length, mut longest, mut nearest, mut bend) = (0.0f32, 0.0f32, f32::INFINITY, 0.0f32);
        let mut bend_vec = [Vec2::ZERO; 2];
        for (s, eye_sign) in [-1.0f32, 1.0].into_iter().enumerate() {
            let mut total = 0.0;
            let mut prev = Vec2::ZERO;
            // The last two points, x unwrapped, y unclamped.
            let (mut q0, mut q1) = (Vec2::ZERO, Vec2::ZERO);
            for k in 0..=segments {
                let t = k as f32 / segments as f32;
                let p = lo + (hi - lo) * spacer.param(t);
                // How far inside twice the eye offset at its altitude the point lies (d_e on
                // the cylinder; the sphere's pole merge fades it, and with it the ring).
                let r = horizontal_radius(p);
                nearest = nearest.min(r - 2.0 * self.projection.eye_offset(r, p.y));
                let raw = self.pixel(p, eye_sign);
                let mut q = raw;
                q.y = q.y.clamp(-clamp_v, clamp_v);
                let dx = (q.x - prev.x) - width * ((q.x - prev.x) / width).round();
                if k > 0 && !(q.y == prev.y && q.y.abs() == clamp_v) {
                    let segment = Vec2::new(dx, q.y - prev.y).length();
                    longest = longest.max(segment);
                    total += segment;
                }
                let unwrapped = Vec2::new(if k > 0 { q1.x + dx } else { raw.x }, raw.y);
                if k >= 2 && unwrapped.y.abs() < clamp_v && q1.y.abs() < clamp_v && q0.y.abs() < clamp_v {
                    let second = unwrapped - 2.0 * q1 + q0;
                    bend = bend.max(second.length());
                    if second.length() > bend_vec[s].length() {
                        bend_vec[s] = second;
                    }
                }
                q0 = q1;
                q1 = unwrapped;
                prev = q;
            }
            length = length.max(total);
        }
        // Near the eye circle, which the paper model and the sphere show on screen (α and the
        // longitude ∝ √(r − d_e)), no stretch is allowed (the exact model puts it at v = ±∞).
        let shows_ring = self.projection.vertical == Vertical::Paper || self.projection.panorama.is_sphere();
        let ring = shows_ring && nearest < 0.0;
        let stretch = if ring { 1.0 } else { MAX_STRETCH };
        // The fastest pixels per radian of azimuth: the longest segment over its step, D/S.
        let residual_px = spacer.turn.map_or(0.0, |d| AZIMUTH_CHORD_RESIDUAL * d * d * segments as f32 * longest);
        EdgeProfile {
            length_px: length.max(segments as f32 * longest / stretch),
            bend_px: bend,
            ring,
            residual_px,
            bend_vec,
        }
    }

    /// `edge_profile` where the image is drawn by pinholes from the eye points (the cubemap's
    /// faces, w the distance along the ray: `SubdivideParams::pinhole_faces`). Between two nodes
    /// the face draws the points of the edge as seen from the eye point that moves linearly from
    /// one node's to the other's; the point is seen from its own eye point E = s·d·(cos λ, 0,
    /// sin λ), which turns with its azimuth. So the drawing is wrong by how far E leaves that
    /// chord, over the distance along the ray: `bend_px` is the largest second difference
    /// |E(k+1) − 2E(k) + E(k−1)| / |P(k) − E(k)| in pixels (both eyes), measured as the error
    /// split reads a bend (the chord's error over n parts about bend·(S/n)²/8). An edge whose
    /// every ray comes from the centre (`Projection::seen_from_centre`) is drawn exactly. The
    /// length is the angle the edge spans (a face magnifies it up to 2× at its sides' middles);
    /// the ring as `edge_profile`'s.
    fn pinhole_profile(&self, lo: Vec3, hi: Vec3, segments: u32) -> EdgeProfile {
        let ppr = self.projection.pixels_per_radian();
        let length_px = lo.cross(hi).length().atan2(lo.dot(hi)) * ppr;
        if self.projection.seen_from_centre(lo, hi) {
            return EdgeProfile { length_px, bend_px: 0.0, ring: false, residual_px: 0.0, bend_vec: [Vec2::ZERO; 2] };
        }
        let spacer = self.spacing().spacer(lo, hi);
        let (mut nearest, mut bend) = (f32::INFINITY, 0.0f32);
        let (mut e0, mut e1, mut depth1) = ([Vec3::ZERO; 2], [Vec3::ZERO; 2], [1.0f32; 2]);
        for k in 0..=segments {
            let p = lo + (hi - lo) * spacer.param(k as f32 / segments as f32);
            let r = horizontal_radius(p);
            let offset = self.projection.eye_offset(r, p.y);
            nearest = nearest.min(r - 2.0 * offset);
            for (s, eye) in [Eye::Left, Eye::Right].into_iter().enumerate() {
                let q = self.projection.project_with_azimuth(p, azimuth(p), eye);
                let e = eye.sign() * offset * Vec3::new(q.u.cos(), 0.0, q.u.sin());
                if k >= 2 {
                    bend = bend.max((e - 2.0 * e1[s] + e0[s]).length() / depth1[s]);
                }
                (e0[s], e1[s], depth1[s]) = (e1[s], e, q.depth);
            }
        }
        EdgeProfile { length_px, bend_px: bend * ppr, ring: nearest < 0.0, residual_px: 0.0, bend_vec: [Vec2::ZERO; 2] }
    }

    /// Divisions of an edge (not capped by N_max: the pre-split handles that), `edge_px` L and
    /// `max_error_px` τ being the triangle's (scaled by its object's level of detail).
    /// `adaptive:length` (eq. 5): a quick 2-segment length first: if it is at most L/2 the edge
    /// stays whole, else N = ceil(l/L) from the 8-segment length (never shorter, as it refines
    /// the same polyline). `adaptive` (the error split): an edge whose 2-segment polyline is at
    /// most L long, away from the eye circle, and whose midpoint bend asks for one part stays
    /// whole; else N = ceil(S·√(bend / 8τ)) from the 8-segment profile, at least l / (8·L)
    /// (no edge longer than 8·L: depth and attributes interpolate over bounded spans), and near
    /// the eye circle at least l / L, as eq. 5 (the second differences miss the ring's √ bend).
    pub(super) fn edge_divisions(&self, a: Vec3, b: Vec3, limits: Limits) -> u32 {
        let Limits { edge_px, max_error_px } = limits;
        let n = match self.params.method {
            0 => return 1,
            1 => return self.params.fixed_n,
            2 => {
                if self.edge_profile(a, b, 2).length_px <= 0.5 * edge_px {
                    return 1;
                }
                (self.edge_profile(a, b, EDGE_SAMPLES).length_px / edge_px).ceil()
            }
            _ => {
                let quick = self.edge_profile(a, b, 2);
                if quick.length_px <= edge_px && quick.straight(1.0, max_error_px) {
                    return 1;
                }
                let p = self.edge_profile(a, b, EDGE_SAMPLES);
                let longest = if p.ring { edge_px } else { ERROR_SPLIT_LENGTH * edge_px };
                let n = parts_for_bend(p.bend_px, EDGE_SAMPLES, max_error_px).max((p.length_px / longest).ceil());
                n.max(p.parts_for_residual(max_error_px))
            }
        };
        if n.is_finite() {
            (n as u32).clamp(1, MAX_EDGE_DIVISIONS)
        } else {
            MAX_EDGE_DIVISIONS
        }
    }

    /// Whether `parts` parts across a band of a piece's rows are enough for the zipper's
    /// diagonals, judged on one of the band's whole diagonals (its quick profile `whole`): a
    /// zipper diagonal spans the band's side step and one part across, and the projection's
    /// mixed term bends it in proportion to that part. `adaptive:length`: the
    /// length within parts × L/2 (a side step of up to L plus a part of L/2 keeps it near L); the
    /// error split: the bend within parts × `ROW_DIAGONAL_ERROR`·τ (at the middle) and the length
    /// within parts × `ERROR_SPLIT_LENGTH`·L. Products, not quotients: the GPU rounds a division
    /// differently in the last bit.
    pub(super) fn diagonal_fits(&self, whole: EdgeProfile, parts: u32, limits: Limits) -> bool {
        let w = parts as f32;
        if self.params.method == SplitRule::Adaptive as u32 {
            2.0 * whole.length_px <= w * limits.edge_px
        } else {
            whole.bend_px <= w * (2.0 * ROW_DIAGONAL_ERROR * limits.max_error_px)
                && whole.length_px <= w * (ERROR_SPLIT_LENGTH * limits.edge_px)
                && whole.residual_px <= w * w * w * (AZIMUTH_RESIDUAL_ERROR * limits.max_error_px)
        }
    }

    /// Divisions of an interior edge of the macro-lattice. Macro edges are about N_max·L long,
    /// but the projection stretches unevenly across a large triangle, so some need more: they may
    /// take up to 2·N_max, and at most `PIECE_DIVISIONS` (a piece then makes at most 32² triangles).
    /// `fixed:N` pieces (K per edge) take N/K (rounded up) on their interior edges: the union is the
    /// regular N-lattice when K divides N.
    pub(super) fn interior_divisions(&self, a: Vec3, b: Vec3, limits: Limits, k: u32) -> u32 {
        if self.params.method == SplitRule::Fixed as u32 {
            return self.params.fixed_n.div_ceil(k.max(1));
        }
        self.edge_divisions(a, b, limits).min(2 * self.params.max_div).min(PIECE_DIVISIONS)
    }

    /// The corners of input triangle t in the viewer frame, snapped to the cut planes.
    pub fn positions(&self, vertices: &[SceneVertex], indices: &[u32], t: usize) -> [Vec3; 3] {
        let view = Mat4::from_cols_array_2d(&self.params.view);
        [0, 1, 2].map(|k| {
            snap_to_cut_planes(view.transform_point3(Vec3::from(vertices[indices[3 * t + k] as usize].position)))
        })
    }

    pub(super) fn load(&self, vertices: &[SceneVertex], indices: &[u32], t: usize) -> Triangle {
        let view = Mat4::from_cols_array_2d(&self.params.view);
        let v = |k: usize| &vertices[indices[3 * t + k] as usize];
        Triangle {
            position: self.positions(vertices, indices, t),
            normal: [0, 1, 2].map(|k| view.transform_vector3(Vec3::from(v(k).normal))),
            color: [0, 1, 2].map(|k| Vec4::from(v(k).color)),
            uv: [0, 1, 2].map(|k| Vec2::from(v(k).uv)),
            tangent: [0, 1, 2].map(|k| {
                let t = unpack_tangent(v(k).tangent);
                view.transform_vector3(t.truncate()).extend(t.w)
            }),
            material: v(0).material,
            object: v(0).object,
        }
    }

    /// The slope k such that a point with |y| > k·r shows in no pixel row
    /// ([`Projection::vertical_limit`], passed to the GPU in `SubdivideParams`).
    pub fn vertical_limit(&self) -> f32 {
        self.params.vertical_limit
    }

    /// Whether a triangle shows in no pixel row: wholly above or wholly below the image's rows
    /// ([`Subdivider::vertical_limit`]). Along a segment with y > 0, y is linear and r convex, so
    /// y/r never falls below its smaller end value (the set y ≥ k·r is convex): corners all
    /// beyond mean the whole triangle is.
    pub fn off_screen_vertically(&self, p: [Vec3; 3]) -> bool {
        let k = self.vertical_limit();
        // A tracked head's eyes are fixed, d_e beside its axis: a point r from that axis may lie
        // r + d_e from an eye, where it rises less steeply (the cylinder's eyes, on their circle,
        // see it along a tangent, from at most r away).
        let pad = if self.projection.head.is_some() { self.projection.eye_radius } else { 0.0 };
        let above = p.iter().all(|q| q.y > k * (horizontal_radius(*q) + pad));
        let below = p.iter().all(|q| q.y < -k * (horizontal_radius(*q) + pad));
        above || below || self.around_dome_antipode(p)
    }

    /// Whether a triangle lies wholly in the fisheye's dropped cone around the point opposite
    /// the dome's axis (`SubdivideParams::antipode_cos`; `around_dome_antipode` in the WGSL).
    pub fn around_dome_antipode(&self, p: [Vec3; 3]) -> bool {
        let c = self.params.antipode_cos;
        if c > 1.0 {
            return false;
        }
        let axis = self.projection.dome_basis()[0];
        p.iter().all(|q| q.dot(axis) < -c * q.length())
    }

    /// Whether input triangle `t` (corners `p` in the viewer frame) is single-sided and every
    /// eye sees its back, so that no stage draws it (the raster culls it, or the fragment stage
    /// discards it: both by its winding on the screen) and the subdivision skips it. With n its
    /// front's normal (counter-clockwise corners), n·(E − p₀) < 0 for every eye point E, which
    /// lie within d_e of the viewer in the horizontal plane on the cylinder and the sphere's
    /// panoramas; by a margin (`BACK_FACE_MARGIN`) so that the GPU agrees. The CAVE's and a
    /// tracked head's eyes are elsewhere: never there. `faces_away` in the WGSL.
    pub fn faces_away(&self, vertices: &[SceneVertex], indices: &[u32], t: usize, p: [Vec3; 3]) -> bool {
        let proj = &self.projection;
        if vertices[indices[3 * t] as usize].flags & SINGLE_SIDED == 0
            || proj.model().eye_model() == EyeModel::Pinhole
            || proj.head.is_some()
        {
            return false;
        }
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        n.dot(p[0]) > proj.eye_radius * Vec2::new(n.x, n.z).length() + BACK_FACE_MARGIN * n.length() * p[0].length()
    }

    /// `plan`: the macro-lattice level K of a part (K² pieces) and its edge counts.
    pub(super) fn plan(&self, tri: &Triangle, part: &[Node; 3]) -> PartSplit {
        let p = part.map(|n| n.position);
        let l = self.limits(tri.object);
        let n = [
            self.edge_divisions(p[0], p[1], l),
            self.edge_divisions(p[1], p[2], l),
            self.edge_divisions(p[2], p[0], l),
        ];
        let m = n[0].max(n[1]).max(n[2]);
        let adaptive = SplitRule::is_adaptive(self.params.method);
        let k = if adaptive {
            m.div_ceil(self.params.max_div.min(PIECE_DIVISIONS)).min(MAX_MACRO_LEVEL)
        } else if self.params.method == SplitRule::Fixed as u32 {
            m.div_ceil(PIECE_DIVISIONS)
        } else {
            1
        };
        PartSplit::new(n, k, adaptive, self.params.max_div)
    }
}
