//! What drawing each node off its projection would buy the error split (a feasibility
//! measure with the CPU twin; nothing in the renderer does this yet).
//!
//! The subdivision puts every node at its projection, so a drawn triangle's error rises from 0
//! at its nodes to about τ between them (docs/results.md, *What the raster pays for*). Drawing
//! each node half that bowl towards the curve would keep the largest error with fewer parts. This
//! example runs the twin (`cpu::subdivide`, sphere 4096×2048, the error split at each τ given),
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
//!   vertex, or a position three or more pieces share) none.
//!
//! `cargo run --release --example node_offsets -- SCENE X,Y,Z 'TAU:RULE;TAU:RULE…'`, e.g.
//! `… -- builtin:demo 0,0,0 '0.4:none;0.7:local'`.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, Vec3};
use twister::core::load::load_scene;
use twister::core::projection::{azimuth, horizontal_radius, Eye, Projection};
use twister::core::settings::{Method, RenderSettings, Split};
use twister::cpu::subdivide::subdivide;
use twister::encoding::subdivide::subdivide_params;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    None,
    Max,
    NoCorners,
    Local,
}

type Error = Box<dyn std::error::Error>;

fn parse_configs(arg: &str) -> Result<Vec<(f32, Rule)>, Error> {
    arg.split(';')
        .map(|c| {
            let (t, r) = c.split_once(':').ok_or_else(|| format!("'{c}': want TAU:RULE"))?;
            let rule = match r {
                "none" => Rule::None,
                "max" => Rule::Max,
                "nocorners" => Rule::NoCorners,
                "local" => Rule::Local,
                _ => return Err(format!("'{r}': the rules are none, max, nocorners, local").into()),
            };
            Ok((t.parse::<f32>().map_err(|e| format!("τ '{t}': {e}"))?, rule))
        })
        .collect()
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        return Err("usage: node_offsets SCENE X,Y,Z 'TAU:RULE;…' (RULE: none, max, nocorners, local)".into());
    }
    let v: Vec<f32> = args[2].split(',').map(str::parse).collect::<Result<_, _>>()?;
    let [x, y, z] = v[..] else { return Err("the viewer is X,Y,Z".into()) };
    let projection = Projection::equirect(4096);
    let scene = load_scene(&args[1], &projection)?;
    let base = RenderSettings::new(projection)
        .with_method(Method::Adaptive(Split::Error))
        .with_viewer(Vec3::new(x, y, z));
    let view = base.view();
    let corner_key = |p: Vec3| [(p.x * 1e4).round() as i64, (p.y * 1e4).round() as i64, (p.z * 1e4).round() as i64];
    let corners: HashSet<[i64; 3]> =
        scene.vertices.iter().map(|v| corner_key(view.transform_point3(Vec3::from(v.position)))).collect();
    let (w_px, h_px) = (projection.width as f64, projection.height as f64);
    let (ppr, ppv) = (projection.pixels_per_radian() as f64, projection.pixels_per_v() as f64);
    // Image position of a point, its azimuth unwrapped towards `theta_ref` as the vertex stage does.
    let pixel = |p: Vec3, theta_ref: f32| -> DVec2 {
        let turn = std::f32::consts::TAU;
        let th0 = azimuth(p);
        let q = projection.project_with_azimuth(p, th0 + turn * ((theta_ref - th0) / turn + 0.5).floor(), Eye::Right);
        DVec2::new(q.u as f64 * ppr + 0.5 * w_px, 0.5 * h_px - q.v as f64 * ppv)
    };
    for (tau, rule) in parse_configs(&args[3])? {
        let settings = base.with_max_error_px(tau);
        let params = subdivide_params(&settings, 0, scene.triangle_count() as u32);
        let out = subdivide(&params, &scene.vertices, &scene.indices);
        let n = out.nodes.len();
        let pos: Vec<Vec3> = out.nodes.iter().map(|v| Vec3::from(v.position)).collect();
        let q: Vec<DVec2> = (0..n).map(|i| pixel(pos[i], out.nodes[i].theta_ref)).collect();
        let w: Vec<f64> = pos.iter().map(|&p| (horizontal_radius(p) as f64).max(1e-4)).collect();
        let tris: Vec<[usize; 3]> =
            out.indices.chunks(3).map(|t| [t[0] as usize, t[1] as usize, t[2] as usize]).collect();
        // Nodes by position (a seam copy, a turn away, apart): every piece has its own copies.
        let mut groups = HashMap::new();
        let group: Vec<usize> = (0..n)
            .map(|i| {
                let key = (pos[i].to_array().map(f32::to_bits), (out.nodes[i].theta_ref / 3.0).round() as i32);
                let next = groups.len();
                *groups.entry(key).or_insert(next)
            })
            .collect();
        let mut copies = vec![0u32; groups.len()];
        for &g in &group {
            copies[g] += 1;
        }
        // An edge two pieces share appears with two different pairs of node copies.
        let edge = |a: usize, b: usize| (group[a].min(group[b]), group[a].max(group[b]));
        let mut pairs: HashMap<(usize, usize), HashSet<(usize, usize)>> = HashMap::new();
        for t in &tris {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                pairs.entry(edge(a, b)).or_default().insert((a.min(b), a.max(b)));
            }
        }
        let (mut widest, mut local) = (vec![DVec2::ZERO; groups.len()], vec![DVec2::ZERO; n]);
        for t in &tris {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let mid = (pos[a].as_dvec3() / w[a] + pos[b].as_dvec3() / w[b]) / (1.0 / w[a] + 1.0 / w[b]);
                let err = pixel(mid.as_vec3(), out.nodes[a].theta_ref) - 0.5 * (q[a] + q[b]);
                let shared = pairs[&edge(a, b)].len() >= 2;
                for k in [a, b] {
                    if err.length() > widest[group[k]].length() {
                        widest[group[k]] = err;
                    }
                    if (copies[group[k]] == 1 || shared) && err.length() > local[k].length() {
                        local[k] = err;
                    }
                }
            }
        }
        let offset: Vec<DVec2> = (0..n)
            .map(|i| {
                let corner = corners.contains(&corner_key(pos[i]));
                0.5 * match rule {
                    Rule::None => DVec2::ZERO,
                    Rule::Max => widest[group[i]],
                    Rule::NoCorners if corner => DVec2::ZERO,
                    Rule::NoCorners => widest[group[i]],
                    Rule::Local if corner || copies[group[i]] >= 3 => DVec2::ZERO,
                    Rule::Local => local[i],
                }
            })
            .collect();
        let mut errors = Vec::new();
        for t in &tris {
            let d = t.map(|i| q[i] + offset[i]);
            let area2 = (d[1] - d[0]).perp_dot(d[2] - d[0]);
            if area2.abs() < 1e-12 {
                continue;
            }
            let lo = d[0].min(d[1]).min(d[2]).floor().max(DVec2::ZERO);
            let hi = d[0].max(d[1]).max(d[2]).ceil().min(DVec2::new(w_px, h_px));
            for py in lo.y as i64..hi.y as i64 {
                for px in lo.x as i64..hi.x as i64 {
                    let c = DVec2::new(px as f64 + 0.5, py as f64 + 0.5);
                    let b0 = (d[1] - c).perp_dot(d[2] - c) / area2;
                    let b1 = (d[2] - c).perp_dot(d[0] - c) / area2;
                    let b2 = 1.0 - b0 - b1;
                    if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                        continue;
                    }
                    let bw = [b0 / w[t[0]], b1 / w[t[1]], b2 / w[t[2]]];
                    let p = (0..3).map(|k| pos[t[k]].as_dvec3() * bw[k]).sum::<glam::DVec3>() / (bw[0] + bw[1] + bw[2]);
                    errors.push((pixel(p.as_vec3(), out.nodes[t[0]].theta_ref) - c).length());
                }
            }
        }
        if errors.is_empty() {
            println!("τ {tau} {rule:?}: no pixel covered");
            continue;
        }
        errors.sort_by(f64::total_cmp);
        let at = |f: f64| errors[((errors.len() - 1) as f64 * f) as usize];
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        println!(
            "τ {tau} {rule:?}: {} triangles; {} pixels: mean {mean:.3} px, p50 {:.3}, p90 {:.3}, p99 {:.3}, max {:.3}",
            tris.len(),
            errors.len(),
            at(0.5),
            at(0.9),
            at(0.99),
            errors[errors.len() - 1]
        );
    }
    Ok(())
}
