//! The ray tracer (`--method trace`) against the independent reference, the slit renderer at one
//! column per slit (`slit:1`, the exact vertical model, to which it converges): the same surface
//! on ≥ 99.9 % of the covered pixels, and where they differ (boundaries), the other render shows
//! the same surface within 1 px.

mod common;

use glam::Mat4;
use twister::core::builtin;
use twister::core::load::load_scene;
use twister::core::settings::Method;
use twister::{Eye, Frame, GpuScene, Projection, RenderSettings, Scene, Vertical};

fn render(scene: &Scene, settings: &RenderSettings) -> Frame {
    let r = common::renderer();
    let gs = GpuScene::upload(&r.gpu, scene).and_then(|g| g.with_bvh(&r.gpu, scene)).expect("upload");
    r.render(&gs, &settings.with_measure_error(true).with_depth(true)).expect("render")
}

/// Same object, distances within `rel`.
fn same_surface(o1: u32, d1: f32, o2: u32, d2: f32, rel: f32) -> bool {
    o1 == o2 && (o1 == 0 || (d1 - d2).abs() <= rel * d1.max(d2))
}

/// Checks trace against slit:1 on one scene; returns the share of differing pixels.
fn check(name: &str, scene: &Scene, projection: Projection) -> f64 {
    let settings = RenderSettings::new(projection);
    let traced = render(scene, &settings.with_method(Method::Trace));
    let slit = render(scene, &settings.with_method(Method::Slit(1)));
    let (w, h) = (projection.width as i64, projection.height as i64);
    let (mut covered, mut differing) = (0usize, 0usize);
    for k in 0..2 {
        let (ot, dt) = (&traced.measurement.as_ref().unwrap().object[k], &traced.depth.as_ref().unwrap()[k]);
        let (os, ds) = (&slit.measurement.as_ref().unwrap().object[k], &slit.depth.as_ref().unwrap()[k]);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if ot[i] == 0 && os[i] == 0 {
                    continue;
                }
                covered += 1;
                if same_surface(ot[i], dt[i], os[i], ds[i], 0.01) {
                    continue;
                }
                differing += 1;
                // A boundary pixel: each render's surface appears in the other within 1 px
                // (columns wrap around the panorama).
                let near = |o: &[u32], d: &[f32], want_o: u32, want_d: f32| {
                    (-1..=1).any(|dy: i64| {
                        (-1..=1).any(|dx: i64| {
                            let (xx, yy) = ((x + dx).rem_euclid(w), y + dy);
                            (0..h).contains(&yy) && {
                                let j = (yy * w + xx) as usize;
                                same_surface(o[j], d[j], want_o, want_d, 0.05)
                            }
                        })
                    })
                };
                assert!(
                    near(os, ds, ot[i], dt[i]) && near(ot, dt, os[i], ds[i]),
                    "{name}, {:?} eye, pixel ({x}, {y}): trace shows object {} at {} m, slit:1 object {} at {} m, \
                     and neither appears within 1 px in the other",
                    Eye::BOTH[k],
                    ot[i],
                    dt[i],
                    os[i],
                    ds[i]
                );
            }
        }
    }
    let share = differing as f64 / covered.max(1) as f64;
    eprintln!("{name}: {differing} of {covered} covered pixels show another surface than slit:1 ({share:.5})");
    assert!(covered > (w * h) as usize / 10, "{name}: only {covered} pixels covered");
    assert!(share <= 1e-3, "{name}: {differing} of {covered} pixels show another surface ({share:.5})");
    share
}

fn exact(width: u32, height: u32) -> Projection {
    Projection { width, height, vertical: Vertical::Exact, ..Projection::default() }
}

#[test]
fn trace_shows_the_surfaces_of_slit_1_on_the_demo_room() {
    check("demo room", &builtin::demo(), exact(480, 120));
}

#[test]
fn trace_shows_the_surfaces_of_slit_1_on_the_bunny_and_a_ring_of_cows() {
    let p = exact(480, 120);
    let mut bunny =
        load_scene(common::asset("stanford-bunny/bun_zipper_res2.obj").to_str().unwrap(), &p).expect("bunny");
    bunny.fit(1.5, &p).unwrap();
    check("bunny", &bunny, p);
    // Eight cows around the viewer, 2.5 m away, facing it (seed 000's scene).
    let mut cow = load_scene(common::asset("cow/cow.obj").to_str().unwrap(), &p).expect("cow");
    cow.fit(2.5, &p).unwrap();
    let mut ring = Scene::new("cow ring");
    for k in 0..8 {
        let mut c = cow.clone();
        c.transform(Mat4::from_rotation_y(k as f32 * std::f32::consts::FRAC_PI_4));
        ring.add_mesh(format!("cow {k}"), &c.vertices, &c.indices);
    }
    assert_eq!(ring.triangle_count(), 8 * cow.triangle_count());
    check("cow ring", &ring, p);
}

#[test]
fn trace_refuses_the_paper_model_and_a_scene_without_its_bvh() {
    let r = common::renderer();
    let scene = builtin::demo();
    let paper = RenderSettings::new(Projection { width: 64, height: 16, ..Projection::default() });
    let gs = GpuScene::upload(&r.gpu, &scene).unwrap();
    let error = |s: &RenderSettings, g: &GpuScene| r.render(g, s).err().expect("an error").to_string();
    let e = error(&paper.with_method(Method::Trace), &gs);
    assert!(e.contains("--vertical exact"), "{e}");
    let e = error(&RenderSettings::new(exact(64, 16)).with_method(Method::Trace), &gs);
    assert!(e.contains("BVH"), "{e}");
    // The sphere has a ray per pixel in either vertical model.
    let sphere = RenderSettings::new(Projection::equirect(64)).with_method(Method::Trace);
    let gs = gs.with_bvh(&r.gpu, &scene).unwrap();
    assert!(r.render(&gs, &sphere).is_ok());
}
