//! Tests of the `subdivide` twin's seam copies: a triangle across the seam drawn at both edges,
//! copies drawn only where they show (the full panoramas, VR180), none on the cubemap.

use std::collections::HashMap;

use super::tests::{run_method, run_method_with_cuts};
use super::*;
use crate::core::panoramas::projection::{azimuth, Eye};
use crate::core::scenes::builtin;
use crate::core::settings::{Method, RenderSettings};

#[test]
fn seam_triangle_gets_a_copy_on_the_other_side() {
    // Cut at the seam (x = 0 behind the viewer) into a part on each side; each part's u range
    // reaches past ±π in one eye, so each also gets a copy a turn away.
    let tri = [[-0.5, 0.0, 3.0], [0.5, 0.0, 3.0], [0.0, 0.5, 3.0]];
    // Alone (no cuts in the frame): the triangle and its copy a turn away.
    let (_, alone) = run_method(tri, Method::Vertex);
    assert_eq!(alone.len(), 6, "the triangle and its seam copy");
    assert!((alone[0].theta_ref - alone[3].theta_ref).abs() > 6.0);
    let out = run_method_with_cuts(tri, Method::Vertex, 1);
    assert_eq!(out.len(), 12, "two parts and their seam copies");
    let refs: Vec<f32> = out.chunks(3).map(|t| t[0].theta_ref).collect();
    let inside: Vec<f32> = refs.iter().copied().filter(|r| r.abs() <= PI).collect();
    assert_eq!(inside.len(), 2);
    assert!(inside.iter().all(|r| (r.abs() - PI).abs() < 0.2) && inside[0] * inside[1] < 0.0, "{refs:?}");
    assert!(refs.iter().filter(|r| r.abs() > PI).all(|r| (r.abs() - PI).abs() < 0.2 + TAU - PI), "{refs:?}");
}

#[test]
fn a_copy_that_only_touches_the_image_edge_is_not_drawn() {
    // The sphere in mono (no eye offset: the parts' reach, measured at their nodes, is 0; as
    // where the pole merge fades the offset), the same triangle cut at the seam: each part's copy
    // a turn away only touches the image's other edge, where it covers no sample.
    let tri = [[-0.5, 0.0, 3.0], [0.5, 0.0, 3.0], [0.0, 0.5, 3.0]];
    let mono = Projection { eye_radius: 0.0, ..Projection::equirect(256) };
    let params = subdivide_params(&RenderSettings::new(mono).with_method(Method::Vertex), 0, 1);
    let v: Vec<SceneVertex> =
        tri.iter().map(|&p| SceneVertex { position: p, normal: [0.0, 0.0, -1.0], ..Default::default() }).collect();
    let sd = Subdivider::new(&params);
    let out = sd.run_with_cuts(&v, &[0, 1, 2], &sd.every_edge_cuts(1, &v, &[0, 1, 2]));
    assert_eq!(out.vertices.len(), 6, "two parts, drawn once each");
    for t in out.vertices.chunks(3) {
        let (lo, hi) = drawn_columns(&mono, t);
        assert!(hi > 0.0 && lo < mono.width as f32, "a part drawn beyond the image: columns {lo}..{hi}");
    }
}

/// Columns (both eyes) a triangle as drawn covers: its corners projected for its copy (θ unwrapped
/// towards its reference azimuth, as the raster stage does), in pixels from the image's left edge.
fn drawn_columns(projection: &Projection, t: &[DrawVertex]) -> (f32, f32) {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for v in t {
        let p = Vec3::from(v.position);
        let theta0 = azimuth(p);
        let theta = theta0 + TAU * ((v.theta_ref - theta0) / TAU + 0.5).floor();
        for eye in Eye::BOTH {
            let x = projection.project_with_azimuth(p, theta, eye).u * projection.pixels_per_radian()
                + 0.5 * projection.width as f32;
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    (lo, hi)
}

#[test]
fn seam_copies_are_drawn_only_where_they_show() {
    // Rooms around the viewer (their floors, walls and ceilings cross the seam behind it) on the
    // full sphere and the cylinder: every triangle is drawn in a copy that meets the image's
    // columns, and few copies lie wholly beyond them (a triangle's copies are tested against its
    // piece's largest eye shift, so some stay: on the sphere at 256 px wide 2 % of the demo
    // room's triangles and 4 % of the box room's, against 7 % and 24 % drawing every copy of a
    // piece; on the cylinder at 480 wide none, against 0.1 % and 20 %).
    // VR180: 4 % of the demo room's triangles and 6 % of the box room's lie beyond its sides
    // (the demo room's: 39 % drawing every piece behind the viewer).
    let box_room = builtin::closed_box("box", Vec3::new(-4.0, -1.7, -3.0), Vec3::new(3.0, 2.3, 4.0));
    for scene in [builtin::demo(), box_room] {
        for projection in [
            Projection::equirect(256),
            Projection::vr180(256),
            Projection { width: 480, height: 120, ..Projection::default() },
        ] {
            let settings = RenderSettings::new(projection);
            let n = scene.triangle_count() as u32;
            let out = subdivide(&subdivide_params(&settings, 0, n), &scene.vertices, &scene.indices);
            let w = projection.width as f32;
            let mut shown: HashMap<Vec<u32>, bool> = HashMap::new();
            let mut beyond = 0;
            for t in out.vertices.chunks(3) {
                let (lo, hi) = drawn_columns(&projection, t);
                let meets = hi > 0.0 && lo < w;
                let key = t.iter().flat_map(|v| v.position.map(f32::to_bits)).collect();
                let seen = shown.entry(key).or_default();
                *seen |= meets;
                beyond += usize::from(!meets);
            }
            let drawn = out.vertices.len() / 3;
            let (name, kind) = (&scene.name, projection.panorama);
            let lost = shown.values().filter(|&&s| !s).count();
            if !kind.wraps() {
                // Pieces whose u range lies behind the viewer are not drawn, nor triangles
                // wholly beyond the image's sides (some within a piece's bound stay).
                assert!(beyond * 10 < drawn, "{name} {kind:?}: {beyond} of {drawn} triangles wholly beyond the image");
                continue;
            }
            assert_eq!(lost, 0, "{name} {kind:?}: triangles drawn in no copy that shows");
            assert!(drawn > shown.len(), "{name} {kind:?}: no seam copies");
            assert!(beyond * 16 < drawn, "{name} {kind:?}: {beyond} of {drawn} copies wholly beyond the image");
        }
    }
    // The cubemap's faces map (u, v) periodically in u: no copies at all.
    let scene = builtin::demo();
    let projection = Projection::cubemap(384);
    let params = subdivide_params(&RenderSettings::new(projection), 0, scene.triangle_count() as u32);
    let out = subdivide(&params, &scene.vertices, &scene.indices);
    let distinct: std::collections::HashSet<Vec<u32>> =
        out.vertices.chunks(3).map(|t| t.iter().flat_map(|v| v.position.map(f32::to_bits)).collect()).collect();
    assert_eq!(distinct.len(), out.vertices.len() / 3, "the cubemap drew a triangle twice");
}
