//! Tests of the `subdivide` twin: lattice conformity, closed meshes, pre-split, axis (the seam's
//! copies: seam_tests.rs).

use super::lattice::strip_node;
use super::spacing::Spacing;
use super::*;
use crate::core::panoramas::projection::{azimuth, wrap_angle, Eye, Vertical};
use crate::core::scenes::builtin;
use crate::core::settings::{Method, RenderSettings, Split, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV};
use crate::encoding::constants::PIECE_DIVISIONS;
use std::collections::HashMap;
use std::f32::consts::FRAC_PI_2;

fn vertex(p: [f32; 3]) -> SceneVertex {
    SceneVertex { position: p, normal: [0.0, 1.0, 0.0], color: [1.0; 4], ..Default::default() }
}

pub(super) fn params_for(
    projection: &Projection,
    method: Method,
    edge_px: f32,
    max_div: u32,
    n: u32,
) -> SubdivideParams {
    // The error split's τ follows L (τ = L/64: 0.5 px at the default L), so that cases that
    // vary L vary τ too.
    let settings = RenderSettings::new(*projection)
        .with_method(method)
        .with_edge_px(edge_px)
        .with_max_error_px(edge_px / 64.0)
        .with_max_div(max_div)
        .with_measure_edges(true);
    subdivide_params(&settings, 0, n)
}

pub(super) fn run_method(tri: [[f32; 3]; 3], method: Method) -> (Projection, Vec<DrawVertex>) {
    let projection = Projection::default();
    let params = params_for(&projection, method, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
    let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
    (projection, subdivide(&params, &v, &[0, 1, 2]).vertices)
}

/// The same in a frame where another triangle switched the cuts around the axis on (bit 0: the
/// quadrant cuts and the square).
pub(super) fn run_method_with_cuts(tri: [[f32; 3]; 3], method: Method, cuts: AxisCuts) -> Vec<DrawVertex> {
    let params = params_for(&Projection::default(), method, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
    let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
    let sd = Subdivider::new(&params);
    sd.run_with_cuts(&v, &[0, 1, 2], &sd.every_edge_cuts(cuts, &v, &[0, 1, 2])).vertices
}

fn area3(t: &[DrawVertex]) -> f32 {
    let p: Vec<Vec3> = t.iter().map(|d| Vec3::from(d.position)).collect();
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
}

/// Area of the footprint of a triangle list on the xz plane.
fn footprint_area(v: &[DrawVertex]) -> f32 {
    v.chunks(3)
        .map(|t| {
            let q: Vec<Vec2> = t.iter().map(|d| Vec2::new(d.position[0], d.position[2])).collect();
            0.5 * (q[1] - q[0]).perp_dot(q[2] - q[0]).abs()
        })
        .sum()
}

#[test]
fn ordinary_triangle_passes_through_the_vertex_method_unchanged() {
    let (_, out) = run_method([[0.5, 0.0, -3.0], [1.5, 0.0, -3.0], [1.0, 0.5, -3.0]], Method::Vertex);
    assert_eq!(out.len(), 3);
    assert!((out[0].theta_ref - (1.0f32).atan2(3.0)).abs() < 1e-6);
}

#[test]
fn triangle_straddling_a_cut_plane_is_cut_only_at_edges_it_shares_with_a_cut_triangle() {
    // Straight ahead, across x = 0, small next to its distance from the axis: it asks for no
    // cuts. In a frame with the quadrant cuts on, it stays whole unless an edge of it is a cut
    // triangle's; with every edge such, its parts take the crossings of edges 0 and 2 with x = 0
    // as corners (the points a cut neighbour makes there), a fan from its centroid: 5 parts.
    let tri = [[-0.5, 0.0, -3.0], [0.7, 0.0, -3.0], [0.2, 0.5, -3.0]];
    let (_, alone) = run_method(tri, Method::Vertex);
    assert_eq!(alone.len(), 3);
    let params = params_for(&Projection::default(), Method::Vertex, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
    let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
    let unshared = FrameCuts { cut_edges: vec![0], ..FrameCuts::every_edge(1, &v, &[0, 1, 2]) };
    assert_eq!(Subdivider::new(&params).run_with_cuts(&v, &[0, 1, 2], &unshared).vertices.len(), 3);
    let out = run_method_with_cuts(tri, Method::Vertex, 1);
    assert_eq!(out.len(), 15);
    let p = tri.map(Vec3::from);
    let expected = [p[0] + (p[1] - p[0]) * (0.5 / 1.2), p[2] + (p[0] - p[2]) * (0.2 / 0.7)];
    for x in expected {
        assert!(
            out.iter().any(|d| d.position[0] == 0.0 && (Vec3::from(d.position) - x).length() < 1e-6),
            "no corner at the crossing {x}"
        );
    }
    let area: f32 = out.chunks(3).map(area3).sum();
    assert!((area - 0.5 * 1.2 * 0.5).abs() < 1e-5, "area {area}");
    assert!(out.chunks(3).all(|t| area3(t) > 0.0));
}

#[test]
fn floor_around_the_axis_is_cut_into_quadrants_minus_the_square_around_the_axis() {
    // Just below the eyes, so that every part shows (none is culled above or below the image).
    let tri = [[-4.0, -1e-4, 3.0], [4.0, -1e-4, 3.0], [0.0, -1e-4, -5.0]];
    let (projection, out) = run_method(tri, Method::Vertex);
    assert!(out.len() >= 3 * 4, "expected a part per quadrant, got {} vertices", out.len());
    let rho = axis_clearance(&projection);
    for d in &out {
        let p = Vec3::from(d.position);
        // Cut points near the axis are computed from far corners: absolute precision ~1e-6·8 m.
        assert!(p.x.abs() + p.z.abs() >= rho - 1e-5, "point {p} inside the square around the axis");
        for eye in Eye::BOTH {
            let pr = projection.project_with_azimuth(p, azimuth(p), eye);
            assert!(pr.u.is_finite() && pr.v.is_finite());
        }
    }
    // The parts tile the triangle minus the square |x| + |z| < ρ (area 2ρ²).
    let full = 0.5 * 8.0 * 8.0;
    let square = 2.0 * rho * rho;
    let originals: Vec<DrawVertex> = out.chunks(3).filter(|t| t[0].theta_ref.abs() <= PI).flatten().copied().collect();
    let got = footprint_area(&originals);
    assert!((got - (full - square)).abs() < 1e-4 * full, "area {got} vs {}", full - square);
    for t in out.chunks(3) {
        let th: Vec<f32> = t
            .iter()
            .map(|d| azimuth(Vec3::from(d.position)))
            .map(|a| t[0].theta_ref + wrap_angle(a - t[0].theta_ref))
            .collect();
        let span = th.iter().cloned().fold(f32::MIN, f32::max) - th.iter().cloned().fold(f32::MAX, f32::min);
        assert!(span <= FRAC_PI_2 + 1e-4, "part spans {span}");
    }
}

#[test]
fn triangle_with_a_vertex_inside_the_eye_circle_is_cut_without_nan() {
    for method in [Method::Vertex, Method::Adaptive(Split::Length), Method::Adaptive(Split::Error), Method::Fixed(4)] {
        for near in [[0.01, -0.5, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.5]] {
            let (projection, out) = run_method([near, [2.0, -0.5, -2.0], [-2.0, -0.5, -2.0]], method);
            assert!(!out.is_empty());
            let rho = axis_clearance(&projection);
            for d in &out {
                let p = Vec3::from(d.position);
                assert!(p.x.abs() + p.z.abs() >= rho - 1e-5, "{p} inside the square");
                assert!(d.position.iter().chain(d.normal.iter()).all(|x| x.is_finite()));
            }
        }
    }
}

#[test]
fn fixed_n_makes_exactly_n_squared_triangles_of_positive_area_tiling_the_triangle() {
    let tri = [[0.4, -0.3, -3.0], [1.7, -0.2, -3.2], [1.1, 0.6, -2.8]];
    let whole = {
        let p = tri.map(Vec3::from);
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    };
    for n in 1..=8 {
        let (_, out) = run_method(tri, Method::Fixed(n));
        assert_eq!(out.len() / 3, (n * n) as usize, "fixed:{n}");
        assert!(out.chunks(3).all(|t| area3(t) > 0.0), "fixed:{n}: a zero-area triangle");
        let total: f32 = out.chunks(3).map(area3).sum();
        assert!((total - whole).abs() < 1e-4 * whole, "fixed:{n}: area {total} vs {whole}");
    }
}

#[test]
fn the_lattice_stores_each_node_once_and_its_triangles_index_them() {
    for m in 1..=PIECE_DIVISIONS {
        let slots: Vec<[u32; 3]> = (0..(m + 1) * (m + 2) / 2).map(|k| slot_node(k, m)).collect();
        for (k, c) in slots.iter().enumerate() {
            assert_eq!(c[0] + c[1] + c[2], m);
            assert_eq!(node_slot(*c, m), k as u32, "level {m}: slot {k} is {c:?}");
        }
    }
    let tri = [[0.4, -0.3, -3.0], [1.7, -0.2, -3.2], [1.1, 0.6, -2.8]];
    for n in [1, 3, 7] {
        let params = params_for(&Projection::default(), Method::Fixed(n), DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
        let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
        let out = subdivide(&params, &v, &[0, 1, 2]);
        // One piece: its (n + 1)(n + 2)/2 lattice nodes, each shared by the triangles around it.
        assert_eq!(out.nodes.len() as u32, (n + 1) * (n + 2) / 2, "fixed:{n}");
        assert_eq!(out.indices.len() as u32, 3 * n * n);
        let distinct: std::collections::BTreeSet<[u32; 3]> =
            out.nodes.iter().map(|d| d.position.map(f32::to_bits)).collect();
        assert_eq!(distinct.len(), out.nodes.len(), "fixed:{n}: a node stored twice");
        assert!(out
            .indices
            .chunks(3)
            .zip(out.vertices.chunks(3))
            .all(|(i, t)| i.iter().zip(t).all(|(&i, v)| out.nodes[i as usize] == *v)));
    }
}

/// Checks a triangulation of the triangle q with `counts` nodes per edge is conforming:
/// every edge is shared by two triangles or lies on the boundary, the boundary edges are
/// exactly the consecutive edge nodes, and the areas add up.
fn check_conforming(counts: [u32; 3]) {
    check_tiling(counts, None);
}

/// A piece's triangulation under test: the lattice, a sliver's strip on a base, or rows of these
/// widths.
enum Tiling {
    Lattice,
    Strip(usize),
    Rows(Vec<u32>),
}

impl From<Option<usize>> for Tiling {
    fn from(strip: Option<usize>) -> Tiling {
        strip.map_or(Tiling::Lattice, Tiling::Strip)
    }
}

/// The piece [`check_tiling`] tiles.
const TILED: [Node; 3] = [
    Node { position: Vec3::new(0.0, 0.0, -3.0), bary: Vec3::X },
    Node { position: Vec3::new(1.3, 0.1, -3.0), bary: Vec3::Y },
    Node { position: Vec3::new(0.4, 1.1, -3.2), bary: Vec3::Z },
];

/// The piece's triangles (the lattice, or the strip on `strip` base) tile it exactly, with nodes
/// spaced evenly and by azimuth: positive area, the piece's winding, every inner edge shared by
/// two triangles, every boundary segment (the edges' own nodes) used once; each triangle's slots
/// name its nodes.
fn check_tiling(counts: [u32; 3], tiling: impl Into<Tiling>) -> usize {
    let tiling = tiling.into();
    let even = check_spaced_tiling(counts, &tiling, Spacing::Even);
    assert_eq!(check_spaced_tiling(counts, &tiling, Spacing::Azimuth), even, "{counts:?}");
    even
}

fn check_spaced_tiling(counts: [u32; 3], tiling: &Tiling, spacing: Spacing) -> usize {
    let q = TILED;
    let node_on_edge = |e: usize, m: u32| edge_point(q[e], q[(e + 1) % 3], m, counts[e], spacing);
    let rows = match tiling {
        Tiling::Rows(widths) => {
            let (base, _) = Rows::base_of(counts);
            let sides = [counts[(base + 2) % 3], counts[(base + 1) % 3]];
            Some(Rows { base, sides, widths: widths.clone() })
        }
        _ => None,
    };
    let triangles = match (tiling, &rows) {
        (Tiling::Strip(base), _) => strip_triangles(counts, *base, &node_on_edge),
        (_, Some(rows)) => rows.triangles(&node_on_edge, spacing),
        _ => lattice_triangles(counts, &q, &node_on_edge, spacing),
    };
    if let Some(rows) = &rows {
        let nodes = rows.nodes(&node_on_edge, spacing);
        assert_eq!(nodes.len() as u32, rows.node_count());
        assert!(triangles.len() as u32 <= rows.candidates());
        for (slots, t) in &triangles {
            assert_eq!(slots.map(|k| nodes[k as usize]), *t, "{counts:?}: slots {slots:?}");
        }
    }
    let strip = match tiling {
        Tiling::Strip(base) => Some(*base),
        _ => None,
    };
    if let Some(base) = strip {
        let [n1, n2] = [counts[(base + 1) % 3], counts[(base + 2) % 3]];
        assert_eq!(triangles.len() as u32, n1 + n2 - 1, "{counts:?}");
        let nodes: Vec<Node> =
            (0..strip_node_count(counts, base)).map(|k| strip_node(counts, base, &node_on_edge, k)).collect();
        for (slots, t) in &triangles {
            assert_eq!(slots.map(|k| nodes[k as usize]), *t, "{counts:?}: slots {slots:?}");
        }
    }
    let normal = (q[1].position - q[0].position).cross(q[2].position - q[0].position);
    for (_, t) in &triangles {
        let n = (t[1].position - t[0].position).cross(t[2].position - t[0].position);
        assert!(n.dot(normal) > 0.0, "{counts:?}: triangle {t:?} turned over");
    }
    let tris: Vec<[Vec3; 3]> = triangles.into_iter().map(|(_, t)| t.map(|n| n.position)).collect();
    let count = tris.len();
    let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    let mut total = 0.0;
    for t in &tris {
        let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        assert!(a > 1e-9, "{counts:?}: zero-area triangle {t:?}");
        total += a;
        for e in 0..3 {
            let (u, v) = (key(t[e]), key(t[(e + 1) % 3]));
            *edges.entry(if u < v { (u, v) } else { (v, u) }).or_default() += 1;
        }
    }
    let whole = 0.5 * (q[1].position - q[0].position).cross(q[2].position - q[0].position).length();
    assert!((total - whole).abs() < 1e-4 * whole, "{counts:?}: area {total} vs {whole}");
    let mut boundary = Vec::new();
    for (e, &count) in counts.iter().enumerate() {
        for m in 0..count {
            let (u, v) = (key(node_on_edge(e, m).position), key(node_on_edge(e, m + 1).position));
            boundary.push(if u < v { (u, v) } else { (v, u) });
        }
    }
    for (edge, n) in &edges {
        let on_boundary = boundary.contains(edge);
        assert_eq!(
            *n,
            if on_boundary { 1 } else { 2 },
            "{counts:?}: edge {edge:?} used {n} times (boundary: {on_boundary})"
        );
    }
    assert!(boundary.iter().all(|b| edges.contains_key(b)), "{counts:?}: a boundary segment is missing (T-junction)");
    count
}

#[test]
fn lattice_is_conforming_for_equal_and_unequal_edge_counts() {
    for a in 1..=9 {
        for b in 1..=9 {
            for c in [1, 2, 3, 5, 9] {
                check_conforming([a, b, c]);
            }
        }
    }
}

#[test]
fn a_slivers_strip_tiles_it_with_fewer_triangles_than_the_lattice() {
    for base in 0..3 {
        for a in 1..=9 {
            for b in 1..=9 {
                let mut counts = [a, b, b];
                counts[base] = 1;
                counts[(base + 1) % 3] = a;
                counts[(base + 2) % 3] = b;
                let (strip, lattice) = (check_tiling(counts, Some(base)), check_tiling(counts, None));
                assert!(strip <= lattice, "{counts:?}: strip {strip} vs lattice {lattice}");
                if a.max(b) >= 4 {
                    assert!(strip < lattice, "{counts:?}: strip {strip} vs lattice {lattice}");
                }
            }
        }
    }
}

#[test]
fn rows_tile_a_piece_whatever_each_rows_width() {
    // Every count triple up to 8, each row's parts drawn at random (1 to 6): the base and the
    // sides keep their own nodes, the triangles cover the piece once, winding kept.
    let mut seed = 7u32;
    let mut next = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        seed >> 16
    };
    for a in 1..=8 {
        for b in 1..=8 {
            for c in 1..=8 {
                let counts = [a, b, c];
                let (base, r) = Rows::base_of(counts);
                let mut widths: Vec<u32> = (0..=r).map(|_| 1 + next() % 6).collect();
                widths[0] = counts[base];
                widths[r as usize] = 0;
                check_tiling(counts, Tiling::Rows(widths));
            }
        }
    }
}

#[test]
fn a_long_thin_parts_bands_tile_it() {
    // The halves of the bands of parts with a base of up to N_max parts and long sides: positive
    // area in the part's winding (or none, corners coinciding), together the whole part.
    let part = [Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.4, 0.0, -3.0), Vec3::new(5.0, 1.0, -3.5)];
    let normal = (part[1] - part[0]).cross(part[2] - part[0]);
    for max_div in [3, 7] {
        for n in [[1, 40, 41], [3, 29, 30], [7, 60, 22], [2, 9, 30], [30, 1, 30], [31, 29, 5]] {
            let point = |(e, j): (usize, u32)| part[e] + (part[(e + 1) % 3] - part[e]) * (j as f32 / n[e] as f32);
            let split = PartSplit { n, k: 5, bands: true };
            let mut total = 0.0;
            for cell in 0..split.pieces(max_div) {
                let [a, b, c] = band_cell(n, max_div, cell).map(point);
                let area = (b - a).cross(c - a).dot(normal) / normal.length();
                assert!(area >= -1e-6, "{n:?} N_max {max_div}: cell {cell} turned over ({area})");
                total += 0.5 * area;
            }
            let whole = 0.5 * normal.length();
            assert!((total - whole).abs() < 1e-4 * whole, "{n:?} N_max {max_div}: area {total} vs {whole}");
        }
    }
}

#[test]
fn vertically_culled_triangles_project_wholly_off_the_image() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut culled = 0;
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection { width: 800, height: 200, vertical, ..Projection::default() };
        let params = params_for(&projection, Method::Adaptive(Split::Length), 32.0, 7, 0);
        let sd = Subdivider::new(&params);
        for _ in 0..3000 {
            let p: [Vec3; 3] = std::array::from_fn(|_| {
                Vec3::new(rng.random_range(-2.0..2.0), rng.random_range(-1.0..3.0), rng.random_range(-2.0..2.0))
            });
            if !sd.off_screen_vertically(p) {
                continue;
            }
            culled += 1;
            for _ in 0..200 {
                let (a, b): (f32, f32) = (rng.random(), rng.random());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let q = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]);
                for eye in Eye::BOTH {
                    if let Some(pr) = projection.project(q, eye) {
                        assert!(
                            pr.v.abs() > projection.half_height_m(),
                            "{vertical:?}: culled triangle {p:?} shows point {q:?}"
                        );
                    }
                }
            }
        }
    }
    assert!(culled > 100, "the test exercised only {culled} culled triangles");
}

#[test]
fn macro_cells_tile_the_lattice() {
    for k in 1..=6 {
        let mut seen = std::collections::HashSet::new();
        for cell in 0..k * k {
            let c = macro_cell(k, cell);
            for v in c {
                assert_eq!(v[0] + v[1] + v[2], k);
            }
            assert!(seen.insert(c), "cell repeated");
        }
    }
}

#[test]
fn subdivided_closed_mesh_stays_closed() {
    let projection = Projection { width: 1200, height: 240, ..Projection::default() };
    let blob = crate::core::scenes::builtin::blob(Vec3::new(0.3, 0.1, -3.0), 1.2);
    let (v, i) = (blob.vertices, blob.indices);
    for (method, edge_px, max_div) in [
        (Method::Adaptive(Split::Length), 32.0f32, 7),
        (Method::Adaptive(Split::Length), 6.0, 3),
        (Method::Adaptive(Split::Length), 3.0, 7),
        (Method::Fixed(5), 0.0, 7),
    ] {
        let params = params_for(&projection, method, edge_px.max(1.0), max_div, (i.len() / 3) as u32);
        let out = subdivide(&params, &v, &i);
        assert!(out.vertices.len() / 3 > i.len() / 3);
        if method == Method::Adaptive(Split::Length) && edge_px <= 6.0 {
            assert!(out.pieces > (i.len() / 3) as u32, "L = {edge_px}: pre-split expected");
        }
        let key = |p: [f32; 3]| p.map(f32::to_bits);
        let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
        for t in out.vertices.chunks(3) {
            for e in 0..3 {
                let (a, b) = (key(t[e].position), key(t[(e + 1) % 3].position));
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
            }
        }
        let open = edges.values().filter(|&&n| n != 2).count();
        assert_eq!(
            open,
            0,
            "{} L={edge_px} N_max={max_div}: {open} edges not shared by exactly two triangles",
            method.name()
        );
        if method == Method::Adaptive(Split::Length) {
            // Eq. 5 bounds each original edge's parts by L; lattice lines inside a large face
            // nearer the viewer than its edges project longer, by up to the depth ratio
            // across the face (here ~1.7).
            assert!(out.max_sub_edge_px <= 2.0 * edge_px, "L={edge_px}: longest edge {} px", out.max_sub_edge_px);
        }
    }
}

/// The twin's passes replaying the GPU's schedules (`passes.rs`) make exactly the triangles the
/// twin makes directly, whatever the schedule and however small the budget (a budget too small
/// for the one submission falls back to chunks, halved until each range fits).
#[test]
fn the_passes_replaying_every_schedule_make_the_twins_triangles() {
    use super::passes::run_scheduled;
    use crate::encoding::schedule::{Capacities, Schedule};
    use rand::{Rng, SeedableRng};

    let cylinder = Projection { width: 480, height: 120, ..Projection::default() };
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut random = crate::core::scenes::scene::Scene::new("random");
    for k in 0..120 {
        let near_axis = k % 3 == 2;
        let c = if near_axis {
            Vec3::new(rng.random_range(-0.05..0.05), rng.random_range(-2.0..2.0), rng.random_range(-0.05..0.05))
        } else {
            Vec3::new(rng.random_range(-8.0..8.0), rng.random_range(-3.0..3.0), rng.random_range(-8.0..8.0))
        };
        let scale = [0.3f32, 6.0, 1.0][k % 3];
        let v: Vec<SceneVertex> = (0..3)
            .map(|_| {
                let d =
                    Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                vertex((c + scale * d).into())
            })
            .collect();
        random.add_mesh("t", &v, &[0, 1, 2]);
    }
    let box_room = builtin::closed_box("box", Vec3::new(-4.0, -1.7, -4.0), Vec3::new(4.0, 2.3, 4.0));
    let cases = [
        (builtin::demo(), RenderSettings::new(cylinder)),
        (builtin::demo(), RenderSettings::new(Projection::equirect(256))),
        (box_room.clone(), RenderSettings::new(cylinder)),
        (box_room, RenderSettings::new(Projection::equirect(128)).with_method(Method::Fixed(3))),
        (random.clone(), RenderSettings::new(cylinder).with_method(Method::Adaptive(Split::Length))),
        (random, RenderSettings::new(Projection::equirect(128))),
    ];
    let sorted = |out: &SubdivideOutput| {
        let mut t: Vec<Vec<u8>> = out.vertices.chunks(3).map(|t| bytemuck::cast_slice(t).to_vec()).collect();
        t.sort();
        t
    };
    let mut cut_frames = 0;
    for (scene, settings) in cases {
        let n = scene.triangle_count() as u32;
        let direct = subdivide(&subdivide_params(&settings, 0, n), &scene.vertices, &scene.indices);
        cut_frames += (direct.cuts != 0) as u32;
        let roomy = Capacities::budget(settings.subdivision.memory_mb, u64::MAX);
        let tiny = Capacities { pieces: 256, triangles: direct.nodes.len().min(direct.indices.len()) as u32 / 8 + 64 };
        for schedule in [Schedule::OneSubmission, Schedule::Chunked { triangles_per_chunk: (n / 3).max(1) }] {
            for budget in [roomy, tiny] {
                let what =
                    format!("{} {:?}, {schedule:?}, budget {budget:?}", scene.name, settings.projection().panorama);
                let out =
                    run_scheduled(&settings, &scene.vertices, &scene.indices, &[], schedule, budget).expect(&what);
                assert_eq!((out.pieces, out.cuts), (direct.pieces, direct.cuts), "{what}");
                assert_eq!(out.max_output, direct.max_output, "{what}: the largest output of one lattice invocation");
                assert!(out.max_pieces >= 1 && out.max_output >= 1, "{what}: the balance counters");
                assert!(
                    out.max_output <= crate::encoding::constants::LATTICE_CHUNK,
                    "{what}: one invocation wrote {} nodes or triangles",
                    out.max_output
                );
                assert_eq!(out.nodes.len(), direct.nodes.len(), "{what}");
                assert!(sorted(&out) == sorted(&direct), "{what}: not the twin's triangles");
            }
        }
    }
    assert!(cut_frames >= 4, "the cases must cut around the axis ({cut_frames})");
}
