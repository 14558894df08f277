//! The slit stage's twin check (tests/twins.rs): both eyes of slit mosaics on the GPU against
//! `cpu::slit`.

use twister::core::scenes::builtin;
use twister::core::settings::Method;
use twister::{Projection, RenderSettings, Renderer, Scene, Vertical};

use super::{common, compare_eyes, frame_outputs, measured, EyeOutputs, Twin};

pub struct Slit;

impl Twin for Slit {
    type Case = (Scene, RenderSettings);
    type Output = EyeOutputs;
    fn cases() -> Vec<(String, Self::Case)> {
        let projection = Projection { width: 192, height: 48, vertical: Vertical::Exact, ..Projection::default() };
        let mut cases: Vec<_> = [1, 4, 16]
            .map(|w| {
                (
                    format!("demo slit:{w}"),
                    (builtin::demo(), RenderSettings::new(projection).with_method(Method::Slit(w))),
                )
            })
            .into();
        // The sphere's tiles, parallel and converging rays.
        for (w, convergence) in [(4, None), (16, Some(2.0))] {
            let sphere = Projection { convergence, ..Projection::equirect(128) };
            cases.push((
                format!("demo on the sphere slit:{w} convergence {convergence:?}"),
                (builtin::demo(), RenderSettings::new(sphere).with_method(Method::Slit(w))),
            ));
        }
        cases.push((
            "demo on VR180 slit:4".into(),
            (builtin::demo(), RenderSettings::new(Projection::vr180(96)).with_method(Method::Slit(4))),
        ));
        cases.push((
            "lit spheres slit:4".into(),
            (
                common::lit_spheres(),
                RenderSettings::new(projection).with_method(Method::Slit(4)).with_shadow_map_size(256),
            ),
        ));
        let shadows = common::ball_over_floor(twister::core::shading::light::LightKind::Directional, true);
        let settings = RenderSettings::new(projection).with_method(Method::Slit(4)).with_shadow_map_size(512);
        cases.push(("ball and screen, directional light's shadow map".into(), (shadows, settings)));
        cases.push((
            "striped floor, anisotropy 16".into(),
            (
                common::striped_floor(),
                RenderSettings::new(projection).with_method(Method::Slit(4)).with_ambient(1.0).with_anisotropy(16),
            ),
        ));
        cases.push((
            "demo slit:4, 4 samples".into(),
            (builtin::demo(), RenderSettings::new(projection).with_method(Method::Slit(4)).with_samples(4)),
        ));
        let screen = common::ball_over_floor(twister::core::shading::light::LightKind::Directional, true);
        let settings = RenderSettings::new(projection).with_method(Method::Slit(4)).with_shadow_map_size(512);
        cases.push((
            "ball and MASK screen slit:4, 4 samples: alpha to coverage".into(),
            (screen, settings.with_samples(4)),
        ));
        // A CAVE wall: every projection method draws it as one pinhole camera per eye.
        let cave = common::cave(1, 96, glam::Vec3::new(0.2, 0.1, 0.3), 25.0);
        cases.push(("demo on a CAVE's left wall".into(), (builtin::demo(), RenderSettings::new(cave))));
        let mut studio = common::lit_spheres();
        studio.environment = Some(common::studio(true));
        cases.push((
            "lit spheres, the studio as the background".into(),
            (studio, RenderSettings::new(projection).with_method(Method::Slit(4)).with_shadow_map_size(256)),
        ));
        cases
    }
    fn gpu(_: &Renderer, (scene, settings): &Self::Case) -> Self::Output {
        frame_outputs(&measured(scene, settings))
    }
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let frame = twister::cpu::render::render(scene, settings).expect("the twins' frame");
        frame.eyes.map(|img| (img.rgba, img.error, img.object, img.distance))
    }
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String> {
        compare_eyes(gpu, cpu, 50, 0.01)
    }
}
