//! Property tests of the `subdivide` twin on closed meshes around the viewer (issue: surround
//! scenes): random closed meshes (icospheres, boxes, tori, the cow) at random positions and
//! sizes — around, above, below and enclosing the viewer — with random settings, with and without
//! the level of detail's relaxed L. The oracle is
//! the mesh itself:
//! - **watertight**: every output edge (by the exact bits of its two end points) is used by
//!   exactly two output triangles, except edges on the square cut around the axis (which no eye
//!   sees) and edges wholly above or below the image (next to culled triangles): no crack, no
//!   T-junction;
//! - **nothing visible removed, nothing added**: every output triangle lies on its input
//!   triangle and outside the square around the axis, and random points of each input triangle
//!   that are outside the square and not off screen are covered by its output.

use std::collections::HashMap;

use glam::Vec3;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::tests::params_for;
use super::*;
use crate::core::projection::{horizontal_radius, PanoramaKind, Vertical};
use crate::core::settings::{Method, Split};

/// A mesh as positions and triangle indices; shared vertices are shared indices, so shared
/// edges have bit-identical end points.
struct Mesh {
    name: String,
    positions: Vec<Vec3>,
    indices: Vec<u32>,
}

fn icosphere(level: u32) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|p| Vec3::from(p).normalize())
    .to_vec();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::new();
        for f in &faces {
            let mut m = [0u32; 3];
            for e in 0..3 {
                let (a, b) = (f[e].min(f[(e + 1) % 3]), f[e].max(f[(e + 1) % 3]));
                m[e] = *mid.entry((a, b)).or_insert_with(|| {
                    positions.push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                    positions.len() as u32 - 1
                });
            }
            next.extend([[f[0], m[0], m[2]], [f[1], m[1], m[0]], [f[2], m[2], m[1]], [m[0], m[1], m[2]]]);
        }
        faces = next;
    }
    Mesh { name: format!("icosphere {level}"), positions, indices: faces.concat() }
}

/// The surface of [−1, 1]³, each face a g×g grid of quads (two triangles each).
fn grid_box(g: u32) -> Mesh {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut id = |c: [u32; 3], positions: &mut Vec<Vec3>| -> u32 {
        *index.entry(c).or_insert_with(|| {
            positions.push(Vec3::from(c.map(|k| 2.0 * k as f32 / g as f32 - 1.0)));
            positions.len() as u32 - 1
        })
    };
    for axis in 0..3 {
        for side in [0, g] {
            for i in 0..g {
                for j in 0..g {
                    let at = |a: u32, b: u32| {
                        let mut c = [0; 3];
                        c[axis] = side;
                        c[(axis + 1) % 3] = a;
                        c[(axis + 2) % 3] = b;
                        c
                    };
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)].map(|c| id(c, &mut positions));
                    indices.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
                }
            }
        }
    }
    Mesh { name: format!("box {g}"), positions, indices }
}

fn torus(n: u32, m: u32) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b) = (std::f32::consts::TAU * i as f32 / n as f32, std::f32::consts::TAU * j as f32 / m as f32);
            let r = 1.0 + 0.4 * b.cos();
            positions.push(Vec3::new(r * a.cos(), 0.4 * b.sin(), r * a.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + j % m;
    let mut indices = Vec::new();
    for i in 0..n {
        for j in 0..m {
            indices.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh { name: format!("torus {n}x{m}"), positions, indices }
}

/// The cow (5,804 triangles), where the third-party assets are.
fn cow() -> Option<Mesh> {
    if !crate::core::assets::present_for_test("random_closed_meshes_around_the_viewer (the cow)") {
        return None;
    }
    let path = crate::core::assets::root().join("cow/cow.obj");
    let scene = crate::core::load::load_obj(&path).unwrap();
    let (lo, hi) = scene.vertices.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), v| {
        (lo.min(Vec3::from(v.position)), hi.max(Vec3::from(v.position)))
    });
    let (centre, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
    let positions = scene.vertices.iter().map(|v| (Vec3::from(v.position) - centre) / half).collect();
    Some(Mesh { name: "cow".into(), positions, indices: scene.indices.clone() })
}

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

/// Runs one case and checks the properties; returns the number of output triangles.
#[allow(clippy::too_many_arguments)]
fn check_case(
    mesh: &Mesh,
    centre: Vec3,
    scale: f32,
    projection: &Projection,
    method: Method,
    edge_px: f32,
    max_div: u32,
    lod_scale: f32,
) -> (usize, u32) {
    let what = format!(
        "{} ×{scale:.2} at {centre:.2}, {}x{} {:?} d_e={} R_T={}, {} L={edge_px:.1} N_max={max_div} LOD×{lod_scale}",
        mesh.name,
        projection.width,
        projection.height,
        projection.vertical,
        projection.eye_radius,
        projection.screen_radius,
        method.name()
    );
    let placed: Vec<Vec3> = mesh.positions.iter().map(|&p| p * scale + centre).collect();
    let vertices: Vec<SceneVertex> = placed
        .iter()
        .map(|p| SceneVertex { position: p.to_array(), normal: [0.0, 1.0, 0.0], color: [1.0; 4], ..Default::default() })
        .collect();
    let triangles = mesh.indices.len() / 3;
    let params = params_for(projection, method, edge_px, max_div, triangles as u32);
    // The visual-field level of detail scales one object's L (uniform over a closed mesh).
    let lod = [lod_scale];
    let sd = Subdivider::with_edge_scale(&params, &lod);
    let rho = params.axis_clearance;
    // Absolute precision of points computed from the mesh's corners.
    let tol = 4e-6 * placed.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));

    let out = sd.run(&vertices, &mesh.indices);
    let cuts = sd.active_cuts(&vertices, &mesh.indices);
    assert_eq!(cuts.axis, out.cuts);
    let originals = distinct_triangles(&out.vertices);
    check_watertight(&what, mesh, &placed, &sd, &originals, tol, rho);

    // Per input triangle (a sample of them): its output lies on it, outside the square, and
    // covers its visible points.
    let mut rng = StdRng::seed_from_u64(triangles as u64);
    let case = OneTriangle { what: &what, mesh, placed: &placed, vertices: &vertices, params, lod: &lod, tol, rho };
    for _ in 0..12 {
        let t = rng.random_range(0..triangles);
        case.check(t, &cuts, &mut rng);
    }
    (originals.len(), out.edge_splits)
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

/// Two meshes as one (the second's indices shifted), each moved and scaled.
fn together(a: &Mesh, (ca, sa): (Vec3, f32), b: &Mesh, (cb, sb): (Vec3, f32)) -> Mesh {
    let mut positions: Vec<Vec3> = a.positions.iter().map(|&p| p * sa + ca).collect();
    let base = positions.len() as u32;
    positions.extend(b.positions.iter().map(|&p| p * sb + cb));
    let indices = a.indices.iter().copied().chain(b.indices.iter().map(|i| i + base)).collect();
    Mesh { name: format!("{} beside, {} around", a.name, b.name), positions, indices }
}

#[test]
fn random_closed_meshes_around_the_viewer_subdivide_watertight_and_whole() {
    let mut meshes = vec![icosphere(1), icosphere(2), grid_box(1), grid_box(3), torus(12, 8)];
    meshes.extend(cow());
    let mut rng = StdRng::seed_from_u64(2026);
    let (mut total, mut edge_splits) = (0, 0);
    for case in 0..60 {
        let mesh = &meshes[case % meshes.len()];
        // Around (enclosing), above, below, beside the viewer; large and small; and beside the
        // viewer inside a room that switches the cuts around the axis on (the mesh is then cut
        // only at the diamonds the room needs, and where it straddles x = 0 or z = 0).
        let (centre, scale) = match case % 5 {
            0 => (
                Vec3::new(rng.random_range(-0.3..0.3), rng.random_range(-0.5..0.5), rng.random_range(-0.3..0.3)),
                rng.random_range(1.5..20.0),
            ),
            1 => (
                Vec3::new(rng.random_range(-0.5..0.5), rng.random_range(1.0..3.0), rng.random_range(-0.5..0.5)),
                rng.random_range(0.3..1.5),
            ),
            2 => (
                Vec3::new(rng.random_range(-0.5..0.5), rng.random_range(-3.0..-1.0), rng.random_range(-0.5..0.5)),
                rng.random_range(0.3..1.5),
            ),
            _ => (
                Vec3::new(rng.random_range(-4.0..4.0), rng.random_range(-1.0..1.0), rng.random_range(-4.0..4.0)),
                rng.random_range(0.2..2.0),
            ),
        };
        let in_room;
        let (mesh, centre, scale) = if case % 5 == 4 {
            let room = (Vec3::new(rng.random_range(-0.3..0.3), 0.0, rng.random_range(-0.3..0.3)), 6.0);
            in_room = together(mesh, (centre, scale), &grid_box(3), room);
            (&in_room, Vec3::ZERO, 1.0)
        } else {
            (mesh, centre, scale)
        };
        let projection = Projection {
            screen_radius: rng.random_range(0.5..3.0),
            eye_radius: [0.0, 0.032, 0.1][rng.random_range(0..3)],
            width: rng.random_range(64..512),
            height: rng.random_range(32..512),
            vertical: if rng.random() { Vertical::Paper } else { Vertical::Exact },
            ..Projection::default()
        };
        // A third of the cases on the full sphere (any convergence, pole merge on or off).
        let projection = if case % 3 == 2 {
            Projection {
                panorama: PanoramaKind::Equirect,
                height: projection.width / 2,
                convergence: [None, Some(2.0)][rng.random_range(0..2)],
                pole_merge: [None, Some(crate::core::projection::DEFAULT_POLE_MERGE)][rng.random_range(0..2)],
                ..projection
            }
        } else {
            projection
        };
        let (method, edge_px, max_div) = match rng.random_range(0..5) {
            0 => (Method::Vertex, 8.0, 7),
            // At most ~300k output triangles: the test runs in debug builds.
            1 => (
                Method::Fixed(rng.random_range(1..=(300_000 / mesh.indices.len()).isqrt().clamp(2, 40) as u32)),
                8.0,
                7,
            ),
            // The error split: τ = L/64 (see `params_for`), 0.06 to 1 px.
            2 => (Method::Adaptive(Split::Error), rng.random_range(4.0..64.0), rng.random_range(1..16)),
            _ => (Method::Adaptive(Split::Length), rng.random_range(4.0..64.0), rng.random_range(1..16)),
        };
        // With the level of detail: L relaxed (peripheral field) or no split (outside).
        let lod_scale = [1.0, 1.0, 2.5, crate::core::lod::NO_SPLIT][rng.random_range(0..4)];
        let (triangles, splits) = check_case(mesh, centre, scale, &projection, method, edge_px, max_div, lod_scale);
        total += triangles;
        edge_splits += splits;
    }
    assert!(total > 10_000, "the cases made only {total} triangles");
    // Triangles cut only at the edges they share with cut ones (`edge_split_parts`).
    assert!(edge_splits >= 20, "only {edge_splits} triangles were cut at shared edges alone");
}

/// One input triangle of a case, subdivided alone (with the frame's cuts): checked as the
/// property test requires (see `check_case`).
struct OneTriangle<'a> {
    what: &'a str,
    mesh: &'a Mesh,
    placed: &'a [Vec3],
    vertices: &'a [SceneVertex],
    params: SubdivideParams,
    lod: &'a [f32],
    tol: f32,
    rho: f32,
}

impl OneTriangle<'_> {
    /// Input triangle `t`'s output lies on its plane, inside it and outside the square around
    /// the axis, and covers 40 random visible points of it.
    fn check(&self, t: usize, cuts: &FrameCuts, rng: &mut StdRng) {
        let OneTriangle { what, mesh, placed, vertices, params, lod, tol, rho } = *self;
        let sd = Subdivider::with_edge_scale(&params, lod);
        let one = SubdivideParams { first_triangle: t as u32, triangle_count: 1, ..params };
        let out = Subdivider::with_edge_scale(&one, lod).run_with_cuts(vertices, &mesh.indices, cuts);
        let corner = [0, 1, 2].map(|k| snap_to_cut_planes(placed[mesh.indices[3 * t + k] as usize]));
        let normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
        if normal.length() == 0.0 {
            return;
        }
        let bary_of = |p: Vec3| -> Vec3 {
            let area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).dot(normal) / normal.length_squared();
            Vec3::new(area(p, corner[1], corner[2]), area(corner[0], p, corner[2]), area(corner[0], corner[1], p))
        };
        let mine = distinct_triangles(&out.vertices);
        for v in mine.iter().flat_map(|t| t.iter()) {
            let p = Vec3::from(v.position);
            let off_plane = (p - corner[0]).dot(normal.normalize()).abs();
            assert!(off_plane <= tol, "{what}: output point {p} is {off_plane} off its triangle's plane");
            assert!(bary_of(p).min_element() >= -1e-4, "{what}: output point {p} outside its triangle");
            assert!(p.x.abs() + p.z.abs() >= rho - tol, "{what}: output point {p} inside the square around the axis");
        }
        let k = sd.vertical_limit();
        for _ in 0..40 {
            let (a, b): (f32, f32) = (rng.random(), rng.random());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let p = corner[0] + a * (corner[1] - corner[0]) + b * (corner[2] - corner[0]);
            let r = horizontal_radius(p);
            // Clearly outside the square and clearly on screen (a margin for the sub-triangles
            // culled whole: those lie wholly beyond the image, and so does this point then).
            let off_screen = p.y.abs() > 0.99 * k * r;
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
            assert!(covered, "{what}: visible point {p} of input triangle {t} is not covered by its output");
        }
    }
}

/// Every output edge of a case is shared by exactly two triangles (its `originals`, seam copies
/// aside), except on the square around the axis, wholly off screen, along an input edge that is
/// open itself, or between slivers narrower than the coordinates' precision (`tol`).
fn check_watertight(
    what: &str,
    mesh: &Mesh,
    placed: &[Vec3],
    sd: &Subdivider,
    originals: &[&[DrawVertex]],
    tol: f32,
    rho: f32,
) {
    // Input edges used other than twice (an open or non-manifold input) may stay open.
    let mut input_edges: HashMap<(Key, Key), u32> = HashMap::new();
    for t in mesh.indices.chunks(3) {
        for e in 0..3 {
            let (a, b) = (placed[t[e] as usize], placed[t[(e + 1) % 3] as usize]);
            *input_edges.entry(edge_key(snap_to_cut_planes(a), snap_to_cut_planes(b))).or_default() += 1;
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
            let (a, b) = (Vec3::from(t[e].position), Vec3::from(t[(e + 1) % 3].position));
            *edges.entry(edge_key(a, b)).or_default() += 1;
        }
    }
    // Slivers: triangles narrower than the coordinates' precision (beside the square around the
    // axis, a part can be ρ wide and metres long; its lattice nodes may round together there).
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
        if *n == 2 || at_edge[edge] {
            continue;
        }
        let (a, b) = (Vec3::from(edge.0.map(f32::from_bits)), Vec3::from(edge.1.map(f32::from_bits)));
        let allowed =
            *n == 1 && ((on_square(a) && on_square(b)) || sd.off_screen_vertically([a, b, a]) || on_open_input(a, b));
        assert!(allowed, "{what}: edge {a} – {b} used by {n} triangles (crack or T-junction)");
    }
}
