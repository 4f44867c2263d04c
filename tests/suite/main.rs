//! The integration tests of rubber-atlas, one binary (one link instead of ten): each module
//! tests one part of the pipeline through the public library or the built program.

mod bodies;
mod cell;
mod cli;
mod critical;
mod domain;
mod family;
mod limits;
mod model;
mod plane;
mod resonance;
mod run;
mod units;
mod verdict;

/// How far the full equations carry the centre of mass from `start` on `body` in time
/// `t_end` (an unbounded path runs away n·|Δζ| in n periods).
pub fn full_model_distance<S: rubber_atlas::Shape>(
    body: &rubber_atlas::Body<S>,
    start: &rubber_atlas::trajectory::Start,
    t_end: f64,
) -> f64 {
    use rubber_atlas::trajectory::{integrate, Model};
    let t = integrate(body, start, Model::Full, t_end, 4, 1e-12, &|| false).unwrap();
    let n = t.t.len() - 1;
    (t.x_c[n] - t.x_c[0]).hypot(t.y_c[n] - t.y_c[0])
}
