//! Single-sided back faces: the subdivision skips a single-sided triangle that every eye sees
//! from behind (`Subdivider::faces_away`). The oracle is the drawing stages' own rule (a
//! single-sided face's fragments are discarded, or culled, by its winding on the screen): the
//! image with the skip must be the image without it, on the CPU twin and on the GPU, but where
//! the skipped triangles showed (see `only_skipped_pixels_change`); and every skipped triangle
//! is seen from behind by every eye point, sampled.

mod common;

use std::collections::BTreeSet;

use glam::Vec3;
use twister::core::scenes::scene::{SceneVertex, SINGLE_SIDED};
use twister::core::settings::Method;
use twister::core::shading::material::Material;
use twister::cpu::raster::raster;
use twister::cpu::subdivide::subdivide;
use twister::encoding::params::raster_params;
use twister::encoding::subdivide::{subdivide_params, SubdivideOutput};
use twister::{Eye, Projection, RenderSettings, Scene, Vertical};

/// Random triangles (`common::random_triangles`: small ones anywhere, big ones around the
/// viewer, ones near the axis), every one single-sided, about half of them seen from behind.
fn single_sided_scene(seed: u64, n: usize) -> Scene {
    common::single_sided(common::random_triangles(seed, n))
}

/// The subdivision of `scene` with the skip and of `plain` (the same unflagged) without it, and
/// the objects (one per triangle here) the skip removed.
fn with_and_without(
    scene: &Scene,
    plain: &Scene,
    settings: &RenderSettings,
) -> (SubdivideOutput, SubdivideOutput, BTreeSet<u32>) {
    let params = subdivide_params(settings, 0, scene.triangle_count() as u32);
    let with = subdivide(&params, &scene.vertices, &scene.indices);
    let without = subdivide(&params, &plain.vertices, &plain.indices);
    let skipped = objects_drawn(&without).difference(&objects_drawn(&with)).copied().collect();
    (with, without, skipped)
}

/// The same scene with no vertex flagged: the subdivision then skips nothing.
fn unflagged(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    for v in &mut s.vertices {
        v.flags &= !SINGLE_SIDED;
    }
    s
}

/// The frames the check draws: the cylinder in both vertical models, the full sphere (the pole
/// merge, the seam), the cubemap, and a viewer moved and turned.
fn settings() -> Vec<(&'static str, RenderSettings)> {
    let cylinder = Projection { width: 320, height: 80, ..Projection::default() };
    vec![
        ("cylinder, paper", RenderSettings::new(cylinder)),
        (
            "cylinder, exact, vertex",
            RenderSettings::new(Projection { vertical: Vertical::Exact, ..cylinder }).with_method(Method::Vertex),
        ),
        ("sphere", RenderSettings::new(Projection::equirect(256))),
        ("cubemap", RenderSettings::new(Projection::cubemap(96))),
        (
            "sphere, viewer moved",
            RenderSettings::new(Projection::equirect(192)).with_viewer(Vec3::new(0.6, 0.3, -0.4)).with_yaw_deg(40.0),
        ),
    ]
}

#[test]
fn mark_sides_follows_the_materials_as_the_fragment_stage_reads_them() {
    let mut scene = Scene::new("sides");
    scene.materials.push(Material { double_sided: 0, ..Default::default() });
    scene.materials.push(Material { double_sided: 1, ..Default::default() });
    // 0: the default material (double-sided); 1: single; 2: double; 7: past the last, which
    // the fragment stage clamps to the last one (double).
    for material in [0, 1, 2, 7] {
        scene.vertices.push(SceneVertex { material, flags: SINGLE_SIDED, ..Default::default() });
    }
    scene.mark_sides();
    let flags: Vec<u32> = scene.vertices.iter().map(|v| v.flags & SINGLE_SIDED).collect();
    assert_eq!(flags, [0, SINGLE_SIDED, 0, 0]);
    // The last material single-sided: an index past it is too.
    scene.materials.push(Material { double_sided: 0, ..Default::default() });
    scene.mark_sides();
    assert_eq!(scene.vertices[3].flags & SINGLE_SIDED, SINGLE_SIDED);
}

/// The objects (one per triangle here) with sub-triangles in `out`.
fn objects_drawn(out: &SubdivideOutput) -> BTreeSet<u32> {
    out.indices.iter().map(|&i| out.nodes[i as usize].object).collect()
}

/// Every pixel that differs between two images of `width` pixels a row (colour or object) shows,
/// without the skip, a triangle the skip removed, or is next to one that does (a multisampled
/// colour's edge pixel, whose centre the object target samples): the other triangles are
/// subdivided and drawn as before. (Such pixels exist: a back face's sub-triangle so thin that
/// the projection's curvature turns its winding over on the screen passes the raster's test and
/// draws a pixel or a few of a face seen from behind — on the sphere, near a pole; the skip
/// removes them; they are few: at most 1 in 150 of the image (140 of 25,600 px for `vertex` on the
/// cylinder, whose parts beside the axis are now cut into bands too), where a face that shows,
/// skipped, would change thousands.)
fn only_skipped_pixels_change(
    name: &str,
    width: usize,
    with: (&[u8], &[u32]),
    without: (&[u8], &[u32]),
    skipped: &BTreeSet<u32>,
) {
    let n = without.1.len();
    let shows_skipped = |i: usize| without.1[i] > 0 && skipped.contains(&(without.1[i] - 1));
    let mut changed = 0;
    for (i, (a, b)) in with.0.chunks(4).zip(without.0.chunks(4)).enumerate() {
        if a != b || with.1[i] != without.1[i] {
            changed += 1;
            let (x, y) = ((i % width) as i64, (i / width) as i64);
            let near = (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy))).any(|(x, y)| {
                let j = y * width as i64 + x.rem_euclid(width as i64);
                j >= 0 && (j as usize) < n && shows_skipped(j as usize)
            });
            assert!(near, "{name}: pixel ({x}, {y}) changed, near no skipped triangle");
        }
    }
    assert!(changed * 150 <= n, "{name}: {changed} of {n} pixels changed");
}

#[test]
fn skipped_triangles_are_seen_from_behind_by_every_eye() {
    let scene = single_sided_scene(11, 240);
    let plain = unflagged(&scene);
    for (name, settings) in settings() {
        let (with, without, skipped) = with_and_without(&scene, &plain, &settings);
        let (kept, all) = (objects_drawn(&with), objects_drawn(&without));
        assert!(skipped.len() * 5 > all.len(), "{name}: {} of {} triangles skipped", skipped.len(), all.len());
        assert!(kept.is_subset(&all), "{name}: the skip drew a triangle that was not drawn");
        // The eye points, sampled: on the circle of d_e about the viewer and within it (the
        // sphere's pole merge moves them in), both eyes, every 3° of longitude.
        let d_e = settings.projection().eye_radius;
        let eyes: Vec<Vec3> = (0..120)
            .flat_map(|k| {
                let a = (k as f32 * 3.0).to_radians();
                [1.0, 0.5, 0.0].map(|f| f * d_e * Vec3::new(a.cos(), 0.0, a.sin()))
            })
            .collect();
        let view = settings.view();
        for t in skipped {
            let p: Vec<Vec3> = (0..3)
                .map(|k| {
                    view.transform_point3(Vec3::from(
                        scene.vertices[scene.indices[3 * t as usize + k] as usize].position,
                    ))
                })
                .collect();
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            for e in &eyes {
                assert!(n.dot(*e - p[0]) < 0.0, "{name}: triangle {t} skipped, but the eye at {e:?} sees its front");
            }
        }
    }
}

#[test]
fn the_twin_draws_the_same_image_without_the_skipped_triangles() {
    let scene = single_sided_scene(12, 240);
    let plain = unflagged(&scene);
    let table = scene.material_table(usize::MAX);
    for (name, settings) in settings() {
        let (with, without, skipped) = with_and_without(&scene, &plain, &settings);
        let background = settings.shading.background;
        let a = raster(&raster_params(&settings), &with.vertices, &table, background);
        let b = raster(&raster_params(&settings), &without.vertices, &table, background);
        for (eye, (a, b)) in Eye::BOTH.iter().zip(a.iter().zip(&b)) {
            let width = a.width as usize;
            only_skipped_pixels_change(
                &format!("{name}, {eye:?}"),
                width,
                (&a.rgba, &a.object),
                (&b.rgba, &b.object),
                &skipped,
            );
        }
    }
}

#[test]
fn the_gpu_draws_the_same_image_without_the_skipped_triangles() {
    let scene = single_sided_scene(12, 240);
    let plain = unflagged(&scene);
    for (name, settings) in settings() {
        let (with, _, skipped) = with_and_without(&scene, &plain, &settings);
        // One sample, so that the object target (each pixel's centre) names what each colour
        // shows; the subdivision is the same whatever the samples.
        let settings = settings.with_samples(1).with_measure_error(true);
        let (a, b) = (common::render(&scene, &settings), common::render(&plain, &settings));
        assert_eq!(a.stats.triangles_out as usize, with.indices.len() / 3, "{name}: the GPU's triangles");
        let (ma, mb) = (a.measurement.as_ref().expect("measured"), b.measurement.as_ref().expect("measured"));
        for (k, eye) in Eye::BOTH.into_iter().enumerate() {
            only_skipped_pixels_change(
                &format!("{name}, {eye:?}"),
                a.eye(eye).width as usize,
                (&a.eye(eye).rgba, &ma.object[k]),
                (&b.eye(eye).rgba, &mb.object[k]),
                &skipped,
            );
        }
    }
}

#[test]
fn a_triangle_is_skipped_only_when_every_eye_sees_its_back() {
    // One triangle 2 m ahead, its front (counter-clockwise seen from the viewer) facing the
    // viewer or turned away, single-sided or not; and one edge-on to the viewer, whose back only
    // some eye points on the eye circle see.
    let projection = Projection::equirect(128);
    let settings = RenderSettings::new(projection);
    let facing = [[-0.5, -0.5, -2.0], [0.5, -0.5, -2.0], [0.0, 0.5, -2.0]];
    let away = [facing[0], facing[2], facing[1]];
    // The plane x = 0.01 seen from the viewer: the eye at x = +d_e (3.2 cm) sees one side,
    // the eye at x = −d_e the other.
    let edge_on = [[0.01, -0.5, -1.5], [0.01, -0.5, -2.5], [0.01, 0.5, -2.0]];
    let drawn = |corners: [[f32; 3]; 3], double_sided: u32| {
        let mut scene = Scene::new("one");
        scene.materials.push(Material { double_sided, ..Default::default() });
        let v: Vec<SceneVertex> = corners
            .iter()
            .map(|&p| SceneVertex { position: p, normal: [0.0, 0.0, 1.0], material: 1, ..Default::default() })
            .collect();
        scene.add_mesh("t", &v, &[0, 1, 2]);
        scene.mark_sides();
        let params = subdivide_params(&settings, 0, 1);
        subdivide(&params, &scene.vertices, &scene.indices).indices.len() / 3
    };
    assert!(drawn(facing, 0) > 0, "a single-sided triangle facing the viewer");
    assert_eq!(drawn(away, 0), 0, "a single-sided triangle turned away");
    assert!(drawn(away, 1) > 0, "a double-sided triangle turned away");
    assert!(drawn(edge_on, 0) > 0, "a single-sided triangle whose back only some eyes see");
    let mirrored = [edge_on[0], edge_on[2], edge_on[1]];
    assert!(drawn(mirrored, 0) > 0, "the same, turned over");
}
