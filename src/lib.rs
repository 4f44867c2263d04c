//! # rubber-atlas
//!
//! Dense atlases of the dynamics of a "rubber" body of revolution (no slipping, no spinning
//! about the vertical) rolling on a plane, after Kilin & Pivovarova, *Bifurcation analysis of
//! the problem of a "rubber" ellipsoid of revolution rolling on a plane*: the equation labels
//! in these docs (`eqsys`, `s1`, `dpsi`, …) are that paper's; docs/model.md states the model
//! as this crate computes it.
//!
//! The crate follows the pipeline of the computation:
//!
//! - [`body`]: the shape behind the [`body::Shape`] trait (the ellipsoid first) and the mass
//!   distribution; U(θ), B(θ), J(θ) of the reduction.
//! - [`reduced`]: the one-degree-of-freedom system `eqsys` at fixed κ, its energy, and the
//!   quadratures for φ, ψ, ω and the paths on the plane.
//! - [`full`]: the full redundant system `eqred` with the kinematics `kin` — the independent
//!   reference for everything reduced.
//! - [`critical`]: the critical set of paper §4 — diagram types, permanent rotations, the cusp,
//!   equilibria, ε_min.
//! - [`limits`]: the edges of the (κ, ε) plane — the high-energy limit N∞(λ), the bottom of
//!   each well, κ → 0 and the separatrices.
//! - [`torus`]: one level set (κ, ε): its components, turning points, period and precession.
//! - [`family`]: the families of tori (the wells a component encloses) and the layouts of an
//!   atlas's component axis.
//! - [`trajectory`]: time histories from either model; [`ode`] wraps the DOP853 integrator.
//! - [`resonance`]: curves N = p/q by continuation, and the fold κ_max.
//! - [`verdict`]: the boundedness hypothesis for one body over the whole (κ, ε) plane, and
//!   the β at which its verdict changes.
//! - [`scene`]: the TOML scene files of atlas runs.
//! - [`atlas`]: the grid driver — work units, rayon over κ-rows, dense per-cell arrays.
//! - [`cf`]: the CF units and attributes every file shares; [`table`]: the tables of
//!   trajectories and curves, column by column.
//! - [`store`]: CSV and HDF5 output, the atlas file and the resume journal.
//! - [`sweep`]: a whole run (resume, shards) and the merge of shards (feature `hdf5`).
//! - `python` (feature `python`): the extension module of the Python package
//!   `rubber_atlas`, built without HDF5.
//!
//! Units are the paper's: length b3, mass m, time √(b3/g). The paper's misprints (in B(θ), the
//! velocity of the centre of mass, θ*, ε_min, the stability of the equator, the type (c)
//! boundary) are corrected as in docs/model.md; each correction is pinned by a test against the
//! full equations or a direct numerical search.

pub mod atlas;
pub mod body;
pub mod cell;
pub mod cf;
pub mod critical;
pub mod dd;
pub mod error;
pub mod family;
pub mod full;
pub mod limits;
pub mod machine;
pub mod ode;
pub mod period_ode;
pub mod quadrature;
pub mod reduced;
pub mod resonance;
pub mod scene;
pub mod store;
#[cfg(feature = "hdf5")]
pub mod sweep;
pub mod table;
pub mod torus;
pub mod trajectory;
pub mod verdict;

#[cfg(feature = "python")]
mod python;

pub use body::{
    Angle, AnyBody, Body, EdgedKind, EdgedShape, Ellipsoid, EllipsoidBody, Profile, ProfileShape,
    Shape,
};
pub use error::{AtlasError, Result};
