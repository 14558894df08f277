//! What drawing each node off its projection buys the error split, measured with the CPU twin:
//! the rules tried before the renderer drew them (`twin`: the renderer's own, `cpu::subdivide::offsets`).
//!
//! The subdivision puts every node at its projection, so a drawn triangle's error rises from 0
//! at its nodes to about τ between them (docs/results.md, *What the raster pays for*). Drawing
//! each node half that bowl towards the curve would keep the largest error with fewer parts. This
//! example runs the twin (`cpu::subdivide`, the sphere at 4096×2048 or, with `cylinder`, the
//! TWISTER display's 3168×600; the error split at each τ given),
//! gives each node a screen offset by one of the rules below, rasterises every output triangle
//! of the right eye at the offset positions (every covered pixel centre, no depth test, the
//! surface point interpolated with w = r as the raster stage does) and prints the display-position
//! error of those pixels. Its figures without offsets match the error pass's to ~5 %.
//!
//! Rules (per node; e(a, b) = where the drawing between nodes a and b puts the point at the
//! screen midpoint, against where it projects):
//! - `none`: no offset (today's drawing);
//! - `max`: half the largest e over every output edge at the node's position (all pieces;
//!   a bound, not something one piece could compute);
//! - `nocorners`: as `max`, but none at the input triangles' corners;
//! - `local`: what a piece could compute for itself with every copy of a node agreeing: a node
//!   no other piece has takes half its largest incident e; a node on an edge two pieces share,
//!   half the largest e of its shared edges (the same edges in both pieces); a corner (an input
//!   vertex, or a position three or more pieces share) none;
//! - `lines`: one offset per straight line the pieces' boundaries lie on (an input edge, a cut
//!   line, a macro line: half the largest e of its segments, as an edge's profile could give
//!   it), taken by every node inside the line (its ends and the input corners none); a node on no
//!   such line, half the largest e of its piece's edges;
//! - `profile`: as `lines`, but a line's error estimated as an edge's profile would give it,
//!   −b·(8/n)²/8 for its n parts, b the largest second difference of its image sampled at 8
//!   equal steps of azimuth between its ends (per line, so the same in every piece); a node on
//!   no line, half the largest of its piece's lines' errors;
//! - `profile-edges`: as `profile` on the lines, but a node on no line as `lines` (half the
//!   largest e its piece's edges measure);
//! - `twin`: the offsets the twin draws (τ here is the split's: `--max-error-px` τ/1.75);
//! - `profile-local`: from the lines' profiles alone, but locally: a segment's error from the
//!   profile's second differences at the two samples around its middle (the larger), −d·(8/n)²/8;
//!   a node inside a line half the larger of its two segments', a node on no line half the
//!   largest of its piece's boundary segments'. No projection beyond the profiles'.
//!
//! `cargo run --release --example node_offsets -- SCENE X,Y,Z 'TAU:RULE;TAU:RULE…' [cylinder]`, e.g.
//! `… -- builtin:demo 0,0,0 '0.4:none;0.7:lines'`.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3, Vec3};
use twister::core::panoramas::projection::{azimuth, horizontal_radius, Eye, Projection};
use twister::core::scenes::load::load_scene;
use twister::core::settings::{Method, RenderSettings, Split};
use twister::cpu::subdivide::spacing::Spacing;
use twister::cpu::subdivide::subdivide;
use twister::encoding::constants::OFFSET_SPLIT_FACTOR;
use twister::encoding::subdivide::subdivide_params;
use twister::encoding::types::DrawVertex;

type Error = Box<dyn std::error::Error>;

/// A straight line of the scene, quantised: its direction up to sign, its point nearest the
/// origin, and the seam copy's turn.
type Line = ([i64; 3], [i64; 3], i32);

#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    None,
    Max,
    NoCorners,
    Local,
    Lines,
    Profile,
    ProfileEdges,
    ProfileLocal,
    Twin,
}

fn parse_configs(arg: &str) -> Result<Vec<(f32, Rule)>, Error> {
    arg.split(';')
        .map(|c| {
            let (t, r) = c.split_once(':').ok_or_else(|| format!("'{c}': want TAU:RULE"))?;
            let rule = match r {
                "none" => Rule::None,
                "max" => Rule::Max,
                "nocorners" => Rule::NoCorners,
                "local" => Rule::Local,
                "lines" => Rule::Lines,
                "profile" => Rule::Profile,
                "profile-edges" => Rule::ProfileEdges,
                "profile-local" => Rule::ProfileLocal,
                "twin" => Rule::Twin,
                _ => return Err(format!(
                    "'{r}': the rules are none, max, nocorners, local, lines, profile, profile-edges, profile-local, twin"
                )
                .into()),
            };
            let tau = t.parse::<f32>().map_err(|e| format!("τ '{t}': {e}"))?;
            if !(tau.is_finite() && tau >= 0.01) {
                return Err(format!("τ '{t}': want a number of pixels ≥ 0.01").into());
            }
            Ok((tau, rule))
        })
        .collect()
}

/// The right eye's image of the sphere, as the vertex stage places points.
struct Image {
    projection: Projection,
    size: DVec2,
}

impl Image {
    /// Image position of a point, its azimuth unwrapped towards `theta_ref`.
    fn pixel(&self, p: Vec3, theta_ref: f32) -> DVec2 {
        let turn = std::f32::consts::TAU;
        let th0 = azimuth(p);
        let q =
            self.projection.project_with_azimuth(p, th0 + turn * ((theta_ref - th0) / turn + 0.5).floor(), Eye::Right);
        DVec2::new(
            q.u as f64 * self.projection.pixels_per_radian() as f64 + 0.5 * self.size.x,
            0.5 * self.size.y - q.v as f64 * self.projection.pixels_per_v() as f64,
        )
    }
}

/// The twin's output with what the rules read: positions, image points, clip w = r, triangles,
/// nodes grouped by position (every piece has its own copies; a seam copy is its own group), and
/// every triangle edge's midpoint error.
struct Mesh<'a> {
    nodes: &'a [DrawVertex],
    pos: Vec<Vec3>,
    q: Vec<DVec2>,
    w: Vec<f64>,
    tris: Vec<[usize; 3]>,
    group: Vec<usize>,
    copies: Vec<u32>,
    /// (a, b, e(a, b)) for every triangle edge.
    edges: Vec<(usize, usize, DVec2)>,
}

impl<'a> Mesh<'a> {
    fn new(image: &Image, nodes: &'a [DrawVertex], indices: &[u32]) -> Self {
        let pos: Vec<Vec3> = nodes.iter().map(|v| Vec3::from(v.position)).collect();
        let q = pos.iter().zip(nodes).map(|(&p, v)| image.pixel(p, v.theta_ref)).collect();
        let w = pos.iter().map(|&p| (horizontal_radius(p) as f64).max(1e-4)).collect();
        let tris: Vec<[usize; 3]> = indices.chunks(3).map(|t| [t[0] as usize, t[1] as usize, t[2] as usize]).collect();
        let mut groups = HashMap::new();
        let group: Vec<usize> = pos
            .iter()
            .zip(nodes)
            .map(|(p, v)| {
                let next = groups.len();
                *groups.entry((p.to_array().map(f32::to_bits), (v.theta_ref / 3.0).round() as i32)).or_insert(next)
            })
            .collect();
        let mut copies = vec![0u32; groups.len()];
        for &g in &group {
            copies[g] += 1;
        }
        let mut mesh = Mesh { nodes, pos, q, w, tris, group, copies, edges: Vec::new() };
        mesh.edges = mesh
            .tris
            .iter()
            .flat_map(|t| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
            .map(|(a, b)| (a, b, mesh.midpoint_error(image, a, b)))
            .collect();
        mesh
    }

    /// e(a, b): the point the drawing (w = r) puts at the screen midpoint of a–b, projected,
    /// against that midpoint.
    fn midpoint_error(&self, image: &Image, a: usize, b: usize) -> DVec2 {
        let (wa, wb) = (self.w[a], self.w[b]);
        let mid = (self.pos[a].as_dvec3() / wa + self.pos[b].as_dvec3() / wb) / (1.0 / wa + 1.0 / wb);
        image.pixel(mid.as_vec3(), self.nodes[a].theta_ref) - 0.5 * (self.q[a] + self.q[b])
    }

    /// An edge by its positions (the same in every piece that has it).
    fn geometric(&self, a: usize, b: usize) -> (usize, usize) {
        (self.group[a].min(self.group[b]), self.group[a].max(self.group[b]))
    }

    /// Whether each edge lies on its piece's boundary (its pair of node copies in one triangle).
    fn boundary(&self) -> Vec<bool> {
        let mut count: HashMap<(usize, usize), u32> = HashMap::new();
        for &(a, b, _) in &self.edges {
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
        self.edges.iter().map(|&(a, b, _)| count[&(a.min(b), a.max(b))] == 1).collect()
    }

    /// Each node's piece (triangles connected by node copies).
    fn pieces(&self) -> Vec<usize> {
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        let mut parent: Vec<usize> = (0..self.pos.len()).collect();
        for t in &self.tris {
            let r0 = root(&mut parent, t[0]);
            for &k in &t[1..] {
                let r = root(&mut parent, k);
                parent[r] = r0;
            }
        }
        (0..self.pos.len()).map(|i| root(&mut parent, i)).collect()
    }

    /// The straight line through a and b (direction up to sign, its point nearest the origin),
    /// quantised, and the copy's turn.
    fn line(&self, a: usize, b: usize) -> Line {
        let (pa, pb) = (self.pos[a].as_dvec3(), self.pos[b].as_dvec3());
        let mut d = (pb - pa).normalize();
        if d.x < -1e-9 || (d.x.abs() <= 1e-9 && (d.y < -1e-9 || (d.y.abs() <= 1e-9 && d.z < 0.0))) {
            d = -d;
        }
        let foot = pa - d * pa.dot(d);
        let quantise = |v: DVec3| [v.x, v.y, v.z].map(|x| (x * 2e3).round() as i64);
        (quantise(d), quantise(foot), (self.nodes[a].theta_ref / 3.0).round() as i32)
    }
}

/// Keeps the larger of two error vectors.
fn widen(slot: &mut DVec2, e: DVec2) {
    if e.length() > slot.length() {
        *slot = e;
    }
}

/// Each node's offset under `rule` (half the chosen error; `corner`: an input triangle's corner).
fn offsets(image: &Image, mesh: &Mesh, rule: Rule, corner: &[bool]) -> Vec<DVec2> {
    let n = mesh.pos.len();
    let mut chosen = vec![DVec2::ZERO; n];
    match rule {
        Rule::None => {}
        Rule::Max | Rule::NoCorners => {
            let mut widest = vec![DVec2::ZERO; mesh.copies.len()];
            for &(a, b, e) in &mesh.edges {
                widen(&mut widest[mesh.group[a]], e);
                widen(&mut widest[mesh.group[b]], e);
            }
            for i in 0..n {
                if rule == Rule::Max || !corner[i] {
                    chosen[i] = widest[mesh.group[i]];
                }
            }
        }
        Rule::Local => {
            // A geometric edge two pieces share comes with two different pairs of node copies.
            let mut pairs: HashMap<(usize, usize), HashSet<(usize, usize)>> = HashMap::new();
            for &(a, b, _) in &mesh.edges {
                pairs.entry(mesh.geometric(a, b)).or_default().insert((a.min(b), a.max(b)));
            }
            for &(a, b, e) in &mesh.edges {
                let shared = pairs[&mesh.geometric(a, b)].len() >= 2;
                for k in [a, b] {
                    if mesh.copies[mesh.group[k]] == 1 || shared {
                        widen(&mut chosen[k], e);
                    }
                }
            }
            for i in 0..n {
                if corner[i] || mesh.copies[mesh.group[i]] >= 3 {
                    chosen[i] = DVec2::ZERO;
                }
            }
        }
        Rule::ProfileLocal => return profile_local(image, mesh, corner),
        // The twin's own (drawn by default where the frame draws offsets): the right eye's.
        Rule::Twin => return twin_offsets(mesh),
        Rule::Lines | Rule::Profile | Rule::ProfileEdges => line_offsets(image, mesh, rule, corner, &mut chosen),
    }
    chosen.iter().map(|&e| 0.5 * e).collect()
}

/// The twin's own offsets (the right eye's), and how many node copies it draws apart.
fn twin_offsets(mesh: &Mesh) -> Vec<DVec2> {
    let mut first = HashMap::new();
    let mut apart = 0;
    for (i, v) in mesh.nodes.iter().enumerate() {
        let f = *first.entry(mesh.group[i]).or_insert(v.offsets);
        if f != v.offsets {
            apart += 1;
            if apart <= 6 && std::env::var_os("SHOW").is_some() {
                println!("  {:?} r {:.4}: {:?} against {:?}", v.position, horizontal_radius(mesh.pos[i]), f, v.offsets);
            }
        }
    }
    if apart > 0 {
        println!("{apart} node copies drawn apart from their first copy");
    }
    mesh.nodes.iter().map(|v| DVec2::new(v.offsets[2] as f64, v.offsets[3] as f64)).collect()
}

/// The offsets of the rules that go by the pieces' boundary lines (`Lines`, `Profile`,
/// `ProfileEdges`), into `chosen`.
fn line_offsets(image: &Image, mesh: &Mesh, rule: Rule, corner: &[bool], chosen: &mut [DVec2]) {
    let n = mesh.pos.len();
    let boundary = mesh.boundary();
    let piece = mesh.pieces();
    let (mut line_max, mut degree) = (HashMap::new(), HashMap::new());
    let (mut piece_max, mut on_lines) = (HashMap::new(), vec![Vec::new(); n]);
    let mut counted = HashSet::new();
    for (&(a, b, e), &on_boundary) in mesh.edges.iter().zip(&boundary) {
        widen(piece_max.entry(piece[a]).or_default(), e);
        if on_boundary {
            let line = mesh.line(a, b);
            widen(line_max.entry(line).or_default(), e);
            if counted.insert(mesh.geometric(a, b)) {
                *degree.entry((line, mesh.group[a])).or_insert(0u32) += 1;
                *degree.entry((line, mesh.group[b])).or_insert(0u32) += 1;
            }
            on_lines[a].push(line);
            on_lines[b].push(line);
        }
    }
    if rule != Rule::Lines {
        profile_errors(image, mesh, &degree, &mut line_max);
    }
    if rule == Rule::Profile {
        piece_max.clear();
        for (&(a, b, _), &on_boundary) in mesh.edges.iter().zip(&boundary) {
            if on_boundary {
                widen(piece_max.entry(piece[a]).or_default(), line_max[&mesh.line(a, b)]);
            }
        }
    }
    for i in 0..n {
        if corner[i] {
            continue;
        }
        if on_lines[i].is_empty() {
            chosen[i] = piece_max.get(&piece[i]).copied().unwrap_or_default();
        }
        for line in &on_lines[i] {
            if degree[&(*line, mesh.group[i])] >= 2 {
                let e = line_max[line];
                widen(&mut chosen[i], e);
            }
        }
    }
}

/// Replaces each line's largest part error by what its profile would estimate: its ends (the
/// positions only one of its segments reaches), its parts (segments), and the largest second
/// difference of its image at 8 equal steps of azimuth between the ends, scaled to a part:
/// −b·(8/n)²/8. A line whose ends are not two keeps its measured error.
fn profile_errors(
    image: &Image,
    mesh: &Mesh,
    degree: &HashMap<(Line, usize), u32>,
    line_max: &mut HashMap<Line, DVec2>,
) {
    let mut node_of = HashMap::new();
    for (i, &g) in mesh.group.iter().enumerate() {
        node_of.entry(g).or_insert(i);
    }
    let mut ends: HashMap<Line, Vec<usize>> = HashMap::new();
    let mut parts: HashMap<Line, u32> = HashMap::new();
    for (&(line, g), &d) in degree {
        *parts.entry(line).or_default() += d;
        if d == 1 {
            ends.entry(line).or_default().push(node_of[&g]);
        }
    }
    for (line, e) in line_max.iter_mut() {
        let Some(&[a, b]) = ends.get(line).map(Vec::as_slice) else { continue };
        let n = (parts[line] / 2).max(1) as f64;
        let (pa, pb) = (mesh.pos[a], mesh.pos[b]);
        let (lo, hi) = if (pa.x, pa.y, pa.z) < (pb.x, pb.y, pb.z) { (pa, pb) } else { (pb, pa) };
        let theta_ref = mesh.nodes[a].theta_ref;
        let samples: Vec<DVec2> = (0..=8)
            .map(|k| {
                let t = Spacing::Azimuth.param(lo, hi, k as f32 / 8.0);
                image.pixel(lo + (hi - lo) * t, theta_ref)
            })
            .collect();
        let mut bend = DVec2::ZERO;
        for k in 1..8 {
            widen(&mut bend, samples[k + 1] - 2.0 * samples[k] + samples[k - 1]);
        }
        *e = -bend * (8.0 / n) * (8.0 / n) / 8.0;
    }
}

/// A line's profile: its canonical ends, its parts, and its image's second differences at the
/// 7 inner samples of 8 equal steps of azimuth (with each sample's 3-D parameter).
struct LineProfile {
    lo: Vec3,
    hi: Vec3,
    parts: f64,
    samples: [(f64, DVec2); 7],
}

impl LineProfile {
    /// The estimated error of the part between 3-D points a and b of the line.
    fn part_error(&self, a: Vec3, b: Vec3) -> DVec2 {
        let axis = (self.hi - self.lo).as_dvec3();
        let t = ((a + b) * 0.5 - self.lo).as_dvec3().dot(axis) / axis.length_squared();
        let k = self.samples.iter().position(|&(s, _)| s >= t).unwrap_or(7);
        let mut d = DVec2::ZERO;
        for j in [k.saturating_sub(1), k.min(6)] {
            widen(&mut d, self.samples[j].1);
        }
        -d * (8.0 / self.parts) * (8.0 / self.parts) / 8.0
    }
}

/// The `profile-local` rule's offsets.
fn profile_local(image: &Image, mesh: &Mesh, corner: &[bool]) -> Vec<DVec2> {
    let n = mesh.pos.len();
    let boundary = mesh.boundary();
    let piece = mesh.pieces();
    // Lines: their segments (each geometric segment once) and each position's degree on them.
    let (mut degree, mut segments, mut counted) = (HashMap::new(), HashMap::new(), HashSet::new());
    for (&(a, b, _), &on_boundary) in mesh.edges.iter().zip(&boundary) {
        if on_boundary && counted.insert(mesh.geometric(a, b)) {
            let line = mesh.line(a, b);
            *degree.entry((line, mesh.group[a])).or_insert(0u32) += 1;
            *degree.entry((line, mesh.group[b])).or_insert(0u32) += 1;
            *segments.entry(line).or_insert(0u32) += 1;
        }
    }
    let mut ends: HashMap<Line, Vec<usize>> = HashMap::new();
    let mut first = HashMap::new();
    for (i, &g) in mesh.group.iter().enumerate() {
        first.entry(g).or_insert(i);
    }
    for (&(line, g), &d) in &degree {
        if d == 1 {
            ends.entry(line).or_default().push(first[&g]);
        }
    }
    let profiles: HashMap<Line, LineProfile> = ends
        .iter()
        .filter_map(|(&line, e)| {
            let &[a, b] = e.as_slice() else { return None };
            let (pa, pb) = (mesh.pos[a], mesh.pos[b]);
            let (lo, hi) = if (pa.x, pa.y, pa.z) < (pb.x, pb.y, pb.z) { (pa, pb) } else { (pb, pa) };
            let at: Vec<(f64, DVec2)> = (0..=8)
                .map(|k| {
                    let t = Spacing::Azimuth.param(lo, hi, k as f32 / 8.0);
                    (t as f64, image.pixel(lo + (hi - lo) * t, mesh.nodes[a].theta_ref))
                })
                .collect();
            let samples = std::array::from_fn(|k| (at[k + 1].0, at[k + 2].1 - 2.0 * at[k + 1].1 + at[k].1));
            Some((line, LineProfile { lo, hi, parts: segments[&line] as f64, samples }))
        })
        .collect();
    let (mut chosen, mut piece_max) = (vec![DVec2::ZERO; n], HashMap::new());
    let mut on_line = vec![false; n];
    for (&(a, b, measured), &on_boundary) in mesh.edges.iter().zip(&boundary) {
        if !on_boundary {
            continue;
        }
        let line = mesh.line(a, b);
        let e = profiles.get(&line).map_or(measured, |p| p.part_error(mesh.pos[a], mesh.pos[b]));
        widen(piece_max.entry(piece[a]).or_default(), e);
        for k in [a, b] {
            on_line[k] = true;
            if degree[&(line, mesh.group[k])] >= 2 {
                widen(&mut chosen[k], e);
            }
        }
    }
    (0..n)
        .map(|i| {
            if corner[i] {
                DVec2::ZERO
            } else if on_line[i] {
                0.5 * chosen[i]
            } else {
                0.5 * piece_max.get(&piece[i]).copied().unwrap_or_default()
            }
        })
        .collect()
}

/// The error of every pixel centre each triangle covers, drawn at the offset positions.
fn pixel_errors(image: &Image, mesh: &Mesh, offset: &[DVec2]) -> Vec<f64> {
    let mut errors = Vec::new();
    for t in &mesh.tris {
        let d = t.map(|i| mesh.q[i] + offset[i]);
        let area2 = (d[1] - d[0]).perp_dot(d[2] - d[0]);
        if area2.abs() < 1e-12 {
            continue;
        }
        let lo = d[0].min(d[1]).min(d[2]).floor().max(DVec2::ZERO);
        let hi = d[0].max(d[1]).max(d[2]).ceil().min(image.size);
        for py in lo.y as i64..hi.y as i64 {
            for px in lo.x as i64..hi.x as i64 {
                let c = DVec2::new(px as f64 + 0.5, py as f64 + 0.5);
                let b0 = (d[1] - c).perp_dot(d[2] - c) / area2;
                let b1 = (d[2] - c).perp_dot(d[0] - c) / area2;
                let b = [b0, b1, 1.0 - b0 - b1];
                if b.iter().any(|&x| x < 0.0) {
                    continue;
                }
                let bw: [f64; 3] = std::array::from_fn(|k| b[k] / mesh.w[t[k]]);
                let p = (0..3).map(|k| mesh.pos[t[k]].as_dvec3() * bw[k]).sum::<DVec3>() / (bw[0] + bw[1] + bw[2]);
                errors.push((image.pixel(p.as_vec3(), mesh.nodes[t[0]].theta_ref) - c).length());
            }
        }
    }
    errors
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 && !(args.len() == 5 && args[4] == "cylinder") {
        return Err("usage: node_offsets SCENE X,Y,Z 'TAU:RULE;…' [cylinder] (RULE: none, max, nocorners, local, lines, profile, profile-edges, profile-local, twin)".into());
    }
    let v: Vec<f32> = args[2].split(',').map(str::parse).collect::<Result<_, _>>()?;
    let [x, y, z] = v[..] else { return Err("the viewer is X,Y,Z".into()) };
    let projection = if args.len() == 5 { Projection::default() } else { Projection::equirect(4096) };
    let image = Image { projection, size: DVec2::new(projection.width as f64, projection.height as f64) };
    let scene = load_scene(&args[1], &projection)?;
    let base =
        RenderSettings::new(projection).with_method(Method::Adaptive(Split::Error)).with_viewer(Vec3::new(x, y, z));
    let view = base.view();
    let key = |p: Vec3| [p.x, p.y, p.z].map(|c| (c * 1e4).round() as i64);
    let corners: HashSet<[i64; 3]> =
        scene.vertices.iter().map(|v| key(view.transform_point3(Vec3::from(v.position)))).collect();
    for (tau, rule) in parse_configs(&args[3])? {
        // τ is the split's tolerance: the renderer splits the sphere at OFFSET_SPLIT_FACTOR × the
        // τ it is given.
        let params =
            subdivide_params(&base.with_max_error_px(tau / OFFSET_SPLIT_FACTOR), 0, scene.triangle_count() as u32);
        let out = subdivide(&params, &scene.vertices, &scene.indices);
        let mesh = Mesh::new(&image, &out.nodes, &out.indices);
        let corner: Vec<bool> = mesh.pos.iter().map(|&p| corners.contains(&key(p))).collect();
        let mut errors = pixel_errors(&image, &mesh, &offsets(&image, &mesh, rule, &corner));
        if errors.is_empty() {
            println!("τ {tau} {rule:?}: no pixel covered");
            continue;
        }
        errors.sort_by(f64::total_cmp);
        let at = |f: f64| errors[((errors.len() - 1) as f64 * f) as usize];
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        println!(
            "τ {tau} {rule:?}: {} triangles; {} pixels: mean {mean:.3} px, p50 {:.3}, p90 {:.3}, p99 {:.3}, max {:.3}",
            mesh.tris.len(),
            errors.len(),
            at(0.5),
            at(0.9),
            at(0.99),
            errors[errors.len() - 1]
        );
    }
    Ok(())
}
