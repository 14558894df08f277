//! A whole frame's schedule as data (as vello's `render.rs` records a scene's): the stages a
//! frame runs, in order, recorded once by [`record_frame`] from the settings and what the
//! engine holds ([`FrameFacts`]). The GPU (`Renderer::render_recorded`) and the CPU twins
//! (`cpu::render::render_recorded`) each run the same recording step by step, a step naming
//! its stage; the subdivision's own passes are the recordings of `encoding::subdivide`, run by
//! the plan its step carries through the one overflow policy (`encoding::schedule::run_plan`).

use crate::core::settings::{Method, RenderSettings};
use crate::encoding::schedule::{Capacities, FramePlan};
use crate::error::{Error, Result};

/// One step of a frame, named by the stage that runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameStep {
    /// `shadow`: the lights' shadow maps, this many.
    Shadow { maps: u32 },
    /// `subdivide`, then `raster`: the scene's triangles subdivided by `plan` (one submission;
    /// or by chunks, the first of at most `chunk` triangles, where the plan says or a buffer
    /// overflowed), each range of output drawn for both eyes into the same targets.
    Subdivided { plan: FramePlan, chunk: u32 },
    /// `slit`: the slit mosaic, slits `width` columns wide (a CAVE wall: one pinhole camera per
    /// eye, as wide as the image).
    Slit { width: u32 },
    /// `trace`: a ray per sample of each pixel.
    Trace,
    /// The targets read back: the colour (kept on the GPU for the live window), and where the
    /// settings measure them the linear colour, the distances, the surface points, and the
    /// error and object targets.
    ReadBack { hdr: bool, depth: bool, positions: bool, error: bool },
    /// `reduce_error`: the error's statistics, an eye at a time (`per_eye`) or both at once.
    ReduceError { per_eye: bool },
}

/// A frame's steps, in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameRecording {
    pub steps: Vec<FrameStep>,
}

/// What an engine holds that a frame's schedule depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameFacts {
    /// The scene's triangles.
    pub triangles: u32,
    /// The shadow maps the lights need (`RenderSettings::shadowed_lighting`).
    pub shadow_maps: u32,
    /// The capacities of the subdivision's buffers kept from the last frame; None: none yet.
    pub cached: Option<Capacities>,
    /// The largest storage binding, bytes.
    pub max_binding: u64,
}

impl FrameRecording {
    /// Whether this recording (handed to an engine) can draw the frame `expected` records
    /// (`record_frame` with the same settings): the same steps in the same order, the same
    /// slits, its subdivision's plan free (one submission or chunks, a first chunk of at least
    /// one triangle) within the settings' memory budget. Else one error naming what differs.
    pub fn check(&self, expected: &FrameRecording) -> Result<()> {
        let within = |plan: FramePlan, budget: Capacities| {
            let fits = |c: Capacities| c.pieces <= budget.pieces && c.triangles <= budget.triangles;
            let want = match plan {
                FramePlan::OneSubmission(want, _) | FramePlan::Chunked { want, .. } => want,
            };
            fits(plan.budget()) && fits(want)
        };
        let same = self.steps.len() == expected.steps.len()
            && self.steps.iter().zip(&expected.steps).all(|(a, b)| match (a, b) {
                (FrameStep::Subdivided { plan, chunk }, FrameStep::Subdivided { plan: settings, .. }) => {
                    *chunk > 0 && within(*plan, settings.budget())
                }
                (a, b) => a == b,
            });
        if same {
            return Ok(());
        }
        Err(Error::setting(
            "recording",
            format!("{:?} cannot draw this frame, whose settings record {:?}", self.steps, expected.steps),
        ))
    }

    /// The plan of its subdivision; None for a frame without one.
    pub fn plan(&self) -> Option<FramePlan> {
        self.steps.iter().find_map(|s| match *s {
            FrameStep::Subdivided { plan, .. } => Some(plan),
            _ => None,
        })
    }
}

/// Records the frame `settings` draw: the shadow maps where the lights need them; the method's
/// drawing — the projection methods' subdivision and raster (one submission unless one
/// binding cannot list the scene's triangles for `plan_cuts`: then by chunks that it can), the
/// slit mosaic (and every method's CAVE wall: one pinhole per eye), or the ray tracer; the
/// read-back; and with the error pass, its reduction.
pub fn record_frame(settings: &RenderSettings, facts: &FrameFacts) -> FrameRecording {
    let mut steps = Vec::new();
    if facts.shadow_maps > 0 {
        steps.push(FrameStep::Shadow { maps: facts.shadow_maps });
    }
    let p = settings.projection();
    steps.push(match settings.subdivision.method {
        Method::Trace => FrameStep::Trace,
        Method::Slit(width) => FrameStep::Slit { width },
        _ if p.model().drawn_as_pinhole() => FrameStep::Slit { width: p.width },
        _ => {
            let budget = Capacities::budget(settings.subdivision.memory_mb, facts.max_binding);
            let plan = FramePlan::first(facts.triangles, facts.cached, budget);
            // The triangles one binding lists for `plan_cuts`.
            let listed = (facts.triangles as u64).min(facts.max_binding / 4).max(1) as u32;
            let plan = if listed < facts.triangles { plan.after_overflow(budget) } else { plan };
            FrameStep::Subdivided { plan, chunk: listed }
        }
    });
    let m = &settings.measure;
    // The ray tracer's surface points are where the pixels' rays meet their hits: from the
    // distances.
    let traced = settings.subdivision.method == Method::Trace;
    let (depth, positions) = if traced { (m.depth || m.positions, false) } else { (m.depth, m.positions) };
    steps.push(FrameStep::ReadBack { hdr: settings.shading.hdr, depth, positions, error: m.error });
    if m.error {
        steps.push(FrameStep::ReduceError { per_eye: m.reduce_per_eye });
    }
    FrameRecording { steps }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::projection::Projection;

    const FACTS: FrameFacts = FrameFacts { triangles: 1000, shadow_maps: 0, cached: None, max_binding: 128 << 20 };

    #[test]
    fn a_frame_records_its_methods_drawing_and_what_it_measures() {
        let settings = RenderSettings::new(Projection { width: 64, height: 16, ..Projection::default() });
        let steps = record_frame(&settings.with_measure_error(true), &FACTS).steps;
        assert!(matches!(steps[0], FrameStep::Subdivided { plan: FramePlan::OneSubmission(..), chunk: 1000 }));
        assert_eq!(
            steps[1..],
            [
                FrameStep::ReadBack { hdr: false, depth: false, positions: false, error: true },
                FrameStep::ReduceError { per_eye: false }
            ]
        );
        let lit = FrameFacts { shadow_maps: 2, ..FACTS };
        let slit = record_frame(&settings.with_method(Method::Slit(4)).with_measure_error(false), &lit).steps;
        assert_eq!(slit[..2], [FrameStep::Shadow { maps: 2 }, FrameStep::Slit { width: 4 }]);
        assert_eq!(slit.len(), 3, "no reduction without the error pass");
        assert_eq!(record_frame(&settings.with_method(Method::Trace), &FACTS).steps[0], FrameStep::Trace);
    }

    #[test]
    fn a_recording_for_other_settings_is_refused_by_name() {
        let settings = RenderSettings::new(Projection { width: 64, height: 16, ..Projection::default() });
        let expected = record_frame(&settings, &FACTS);
        let chunked = FrameStep::Subdivided {
            plan: FramePlan::first(1000, None, Capacities { pieces: 9, triangles: 9 }),
            chunk: 7,
        };
        let other_plan = FrameRecording { steps: [vec![chunked], expected.steps[1..].to_vec()].concat() };
        assert!(other_plan.check(&expected).is_ok(), "the plan is free");
        for bad in [
            FrameRecording { steps: vec![] },
            FrameRecording { steps: [vec![FrameStep::Slit { width: 0 }], expected.steps[1..].to_vec()].concat() },
            FrameRecording {
                steps: [
                    vec![FrameStep::Subdivided {
                        plan: FramePlan::first(1, None, Capacities { pieces: 1, triangles: 1 }),
                        chunk: 0,
                    }],
                    expected.steps[1..].to_vec(),
                ]
                .concat(),
            },
            FrameRecording { steps: [expected.steps.clone(), vec![FrameStep::ReduceError { per_eye: true }]].concat() },
            // Buffers beyond the settings' memory budget.
            FrameRecording {
                steps: [
                    vec![FrameStep::Subdivided {
                        plan: FramePlan::first(1000, None, Capacities { pieces: u32::MAX, triangles: u32::MAX }),
                        chunk: 1000,
                    }],
                    expected.steps[1..].to_vec(),
                ]
                .concat(),
            },
        ] {
            let e = bad.check(&expected).expect_err("refused").to_string();
            assert!(e.starts_with("recording: "), "{e}");
        }
    }

    #[test]
    fn more_triangles_than_one_binding_lists_are_subdivided_by_chunks() {
        let settings = RenderSettings::new(Projection { width: 64, height: 16, ..Projection::default() });
        let facts = FrameFacts { triangles: 5000, max_binding: 4 * 3000, ..FACTS };
        let plan = record_frame(&settings, &facts).plan();
        assert!(matches!(plan, Some(FramePlan::Chunked { .. })), "{plan:?}");
        assert!(record_frame(&settings, &facts)
            .steps
            .contains(&FrameStep::Subdivided { plan: plan.unwrap(), chunk: 3000 }));
    }
}
