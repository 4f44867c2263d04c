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
