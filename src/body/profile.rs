//! A body of revolution of the user's own, given by a table of points of its meridian
//! (docs/bodies.md, "Your own body"). The points are joined by circular arcs, tangent where
//! they meet (an arc spline through every point): on each arc U = ρ_a sinθ − z_a cosθ +
//! r (1 − cos(θ − θ_a)) from a point (ρ_a, z_a) of the arc whose outward normal is at θ_a, so
//! U + U″ = r, the arc's radius, and the reduction of paper §2 (`oned`) takes U as it takes the
//! cut balls' (module `edged`). Points marked as edges are sharp circles of the body
//! (U + U″ = 0 while the normal turns round them); a flat end of the table is a face.

use super::{Angle, Shape};
use crate::dd::DoubleDouble;
use crate::error::{AtlasError, Result};
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::sync::Mutex;

/// The most points a profile may have (each smooth stretch between two points is two arcs, and
/// every arc's end is a kink at which the cell solver splits its integrals).
pub const MAX_PROFILE_POINTS: usize = 2000;

/// The largest |ρ| or |z| of a profile's point, in any unit the user chooses.
pub const MAX_PROFILE_COORDINATE: f64 = 1e6;

/// One smooth part of the meridian: a circular arc of radius `radius` (0: a sharp edge, a
/// circle of the body round which the normal turns), over the normal angles
/// [`theta_start`, `theta_end`]. Its anchor is the point (ρ_a, z_a) of the arc where the
/// outward normal is at θ_a (one of its ends), in the table's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileArc {
    /// The normal angle where the arc starts (θ at which it first touches the plane).
    pub theta_start: f64,
    /// The normal angle where it ends.
    pub theta_end: f64,
    /// The radius of curvature of the meridian on it: U + U″ (0 on an edge).
    pub radius: f64,
    /// θ_a, the normal angle at the anchor (`theta_start` or `theta_end`).
    pub anchor_theta: f64,
    /// ρ_a, the anchor's distance from the axis.
    pub anchor_rho: f64,
    /// z_a, the anchor's height along the axis in the table's frame.
    pub anchor_z: f64,
    anchor_sin: f64,
    anchor_cos: f64,
    /// θ_end − θ_start to full relative precision (from the angles' offsets from the chords,
    /// not their difference: near π each holds only an absolute 4e-16).
    turn: f64,
}

impl ProfileArc {
    fn new(
        (theta_start, theta_end, turn): (f64, f64, f64),
        radius: f64,
        anchor_theta: f64,
        anchor: [f64; 2],
    ) -> Self {
        // Exact at the poles: sin π as a double is 1.2e-16.
        let (anchor_sin, anchor_cos) = if anchor_theta == 0.0 {
            (0.0, 1.0)
        } else if anchor_theta == PI {
            (0.0, -1.0)
        } else {
            libm::sincos(anchor_theta)
        };
        Self {
            theta_start,
            theta_end,
            radius,
            anchor_theta,
            anchor_rho: anchor[0],
            anchor_z: anchor[1],
            anchor_sin,
            anchor_cos,
            turn,
        }
    }

    /// The centre of the arc's circle, (ρ, z) in the table's frame: the anchor less r times
    /// the outward normal (sin θ_a, −cos θ_a).
    pub fn centre(&self) -> [f64; 2] {
        [
            self.anchor_rho - self.radius * self.anchor_sin,
            self.anchor_z + self.radius * self.anchor_cos,
        ]
    }

    /// The arc's point where the outward normal is at θ: the anchor itself at θ_a, else the
    /// centre plus r times the normal (sin θ, −cos θ).
    fn point(&self, theta: f64) -> [f64; 2] {
        if theta == self.anchor_theta {
            return [self.anchor_rho, self.anchor_z];
        }
        let [rho, z] = self.centre();
        let (s, c) = libm::sincos(theta);
        [rho + self.radius * s, z - self.radius * c]
    }

    /// sin d and cos d, d = θ − θ_a, for sinθ = `s` ≥ 0 and cosθ = `c`.
    #[inline]
    fn angle_from_anchor(&self, s: f64, c: f64) -> (f64, f64) {
        (
            s * self.anchor_cos - c * self.anchor_sin,
            c * self.anchor_cos + s * self.anchor_sin,
        )
    }
}

/// 1 − cos d from sin d and cos d, without cancellation for small d.
#[inline]
fn one_minus_cos(sin_d: f64, cos_d: f64) -> f64 {
    if cos_d > 0.0 {
        sin_d * sin_d / (1.0 + cos_d)
    } else {
        1.0 - cos_d
    }
}

/// How close (relative to the radius) the centres and radii of two neighbouring arcs must be
/// for them to be one arc: points of one circle give arcs that differ by 1e-14 … 1e-13 (the
/// rounding of the fit, larger as the points crowd).
pub const SAME_CIRCLE: f64 = 1e-12;

/// `arcs` with neighbours on one circle (to [`SAME_CIRCLE`]) joined into one arc: a joint
/// where U″ does not jump would only split the integrals for nothing. The joined arc runs
/// from the first one's start point to the last one's end point (points of the table, or of
/// the biarcs' joints), with the radius of the chord between them and the normal's turn, and
/// is anchored at a pole if it reaches one (U′/sinθ is exact there), else at its start.
fn merge_arcs_of_one_circle(arcs: Vec<ProfileArc>) -> Vec<ProfileArc> {
    let same = |a: &ProfileArc, b: &ProfileArc| {
        let (ca, cb) = (a.centre(), b.centre());
        let scale = SAME_CIRCLE * a.radius.max(b.radius);
        a.radius > 0.0
            && b.radius > 0.0
            && (a.radius - b.radius).abs() <= scale
            && (ca[0] - cb[0]).abs() <= scale
            && (ca[1] - cb[1]).abs() <= scale
    };
    let mut groups: Vec<Vec<ProfileArc>> = Vec::new();
    for arc in arcs {
        match groups.last_mut() {
            // Against the group's first arc, so that a slow drift does not chain arcs of
            // different circles together.
            Some(group) if same(&group[0], &arc) => group.push(arc),
            _ => groups.push(vec![arc]),
        }
    }
    groups
        .into_iter()
        .map(|group| {
            let (first, last) = (group[0], group[group.len() - 1]);
            if group.len() == 1 {
                return first;
            }
            let (start, end) = (first.point(first.theta_start), last.point(last.theta_end));
            let turn = group.iter().map(|a| a.turn).sum::<f64>();
            let radius = chord_length(start, end) / (2.0 * (0.5 * turn).sin());
            let (anchor_theta, anchor) = if last.theta_end == PI {
                (PI, end)
            } else {
                (first.theta_start, start)
            };
            ProfileArc::new(
                (first.theta_start, last.theta_end, turn),
                radius,
                anchor_theta,
                anchor,
            )
        })
        .collect()
}

/// A validated meridian: the table as given (bottom to top) and the arc spline through it.
#[derive(Debug)]
pub struct Profile {
    points: Vec<[f64; 3]>,
    arcs: Vec<ProfileArc>,
    /// The normal angles where one arc meets the next: the kinks of U.
    joints: Vec<f64>,
    /// (sin, cos) of each joint: an angle is placed among them without its θ.
    joint_sin_cos: Vec<(f64, f64)>,
    faces: [bool; 2],
}

impl PartialEq for Profile {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
    }
}

impl Eq for Profile {}

/// The profiles made so far, each once: a body holds a `&'static Profile` (bodies are `Copy`),
/// and the same table asked for again (every call of a sweep) is the same profile.
static PROFILES: Mutex<Vec<&'static Profile>> = Mutex::new(Vec::new());

fn refuse<T>(reason: String) -> Result<T> {
    Err(AtlasError::Profile { reason })
}

/// The direction angle of the chord from `a` to `b` in the (ρ, z) plane.
fn chord_angle(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[1] - a[1]).atan2(b[0] - a[0])
}

fn chord_length(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// a b − c d with one rounding's error or so, however they cancel (Kahan's algorithm with
/// fused multiply-adds).
fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let error = (-c).mul_add(d, cd);
    a.mul_add(b, -cd) + error
}

impl Profile {
    /// The profile through `points`, rows (ρ, z) or (ρ, z, edge) with edge 1 at a sharp edge
    /// and 0 elsewhere, from one pole to the other (either way round): the first and the last
    /// on the axis (ρ = 0), every other point off it, lengths in any one unit. A profile made
    /// before from the same table is returned again. Refused, with the point and the reason
    /// in one line, where the table is not a convex meridian the arc spline can follow.
    pub fn from_points(points: &[Vec<f64>]) -> Result<&'static Profile> {
        let (rows, reversed) = Self::checked_rows(points)?;
        let mut made = PROFILES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = made.iter().find(|p| p.points == rows) {
            return Ok(p);
        }
        let profile = Self::fit(rows, reversed)?;
        let leaked: &'static Profile = Box::leak(Box::new(profile));
        made.push(leaked);
        Ok(leaked)
    }

    /// The rows as (ρ, z, edge), bottom pole first, each value checked, and whether they were
    /// given top pole first (reversed here).
    fn checked_rows(points: &[Vec<f64>]) -> Result<(Vec<[f64; 3]>, bool)> {
        let n = points.len();
        if n < 3 {
            return refuse(format!(
                "has {n} points; a meridian needs at least 3 (a pole, a point off the axis, the other pole)"
            ));
        }
        if n > MAX_PROFILE_POINTS {
            return refuse(format!(
                "has {n} points; at most {MAX_PROFILE_POINTS} are taken"
            ));
        }
        let mut rows = Vec::with_capacity(n);
        for (i, p) in points.iter().enumerate() {
            if p.len() != 2 && p.len() != 3 {
                return refuse(format!(
                    "point {i} (counted from 0) has {} values; each is (rho, z) or (rho, z, edge)",
                    p.len()
                ));
            }
            for (name, &x) in ["rho", "z"].iter().zip(p) {
                if !x.is_finite() || x.abs() > MAX_PROFILE_COORDINATE {
                    return refuse(format!(
                        "point {i} (counted from 0) has {name} = {}; it must be a finite number of magnitude at most 1e6",
                        crate::error::show(x)
                    ));
                }
            }
            let edge = p.get(2).copied().unwrap_or(0.0);
            if edge != 0.0 && edge != 1.0 {
                return refuse(format!(
                    "point {i} (counted from 0) has edge = {}; it must be 0 (smooth) or 1 (a sharp edge)",
                    crate::error::show(edge)
                ));
            }
            rows.push([p[0], p[1], edge]);
        }
        if rows[0][0] != 0.0 || rows[n - 1][0] != 0.0 {
            return refuse(
                "must start and end on the axis (rho = 0 at the first and the last point: the poles)"
                    .into(),
            );
        }
        if let Some(i) = (1..n - 1).find(|&i| rows[i][0] <= 0.0) {
            return refuse(format!(
                "point {i} (counted from 0) has rho = {}; only the first and the last point lie on the axis, the others at rho > 0",
                crate::error::show(rows[i][0])
            ));
        }
        if rows[0][1] == rows[n - 1][1] {
            return refuse("has both poles at the same height: the body has no thickness".into());
        }
        if let Some(i) = (0..n - 1).find(|&i| rows[i][..2] == rows[i + 1][..2]) {
            return refuse(format!(
                "repeats point {i} as point {} (counted from 0)",
                i + 1
            ));
        }
        let reversed = rows[0][1] > rows[n - 1][1];
        if reversed {
            rows.reverse();
        }
        Ok((rows, reversed))
    }

    /// The arc spline through the rows (bottom pole first; `reversed`: given top pole first,
    /// which the refusals count their points in).
    fn fit(rows: Vec<[f64; 3]>, reversed: bool) -> Result<Self> {
        let n = rows.len();
        // (A table given top pole first was refused by the points' places bottom first.)
        let given = |i: usize| if reversed { n - 1 - i } else { i };
        let at = |i: usize| [rows[i][0], rows[i][1]];
        // A first or last stretch along a circle z = const from the axis is a flat face, and
        // the point where it ends is an edge.
        let faces = [rows[1][1] == rows[0][1], rows[n - 2][1] == rows[n - 1][1]];
        let first = usize::from(faces[0]);
        let last = if faces[1] { n - 2 } else { n - 1 };
        if last <= first {
            return refuse("is two faces and nothing between them".into());
        }
        let edge =
            |i: usize| rows[i][2] == 1.0 || (i == first && faces[0]) || (i == last && faces[1]);
        // The tangent's direction angle at every smooth point: 0 at the bottom pole, π at the
        // top, and elsewhere that of the circle through the point and its two neighbours. With
        // it, to full relative precision, its offsets from the chords either side: `before`,
        // the tangent where the meridian arrives at a point less the chord into it, and
        // `after`, the chord out of it less the tangent where it leaves. The arcs' radii
        // divide by these (not by differences of angles near π, which hold an absolute 4e-16
        // each: a biarc turning 3.2e-4 to a flat top had its radius 8.6e-13 off, relative,
        // and the period of a libration in that well, T ∝ r^−½, 4.3e-13 off).
        let mut tangent = vec![f64::NAN; n];
        let mut before = vec![f64::NAN; n];
        let mut after = vec![f64::NAN; n];
        // π less the chord angle from `a` to `b`, where that is small (up to a top pole).
        let from_pi = |a: [f64; 2], b: [f64; 2]| (b[1] - a[1]).atan2(a[0] - b[0]);
        for i in (first..=last).filter(|&i| !edge(i)) {
            tangent[i] = if i == 0 {
                after[0] = chord_angle(at(0), at(1));
                0.0
            } else if i == n - 1 {
                before[i] = from_pi(at(i - 1), at(i));
                PI
            } else {
                let (a, b, c) = (at(i - 1), at(i), at(i + 1));
                // The turn between the chords from the cross and dot products of their
                // directions (each with one rounding: `difference_of_products`; of unit vectors,
                // so that neither underflows on a tiny body nor overflows on a huge one).
                let (l1, l2) = (chord_length(a, b), chord_length(b, c));
                let u = [(b[0] - a[0]) / l1, (b[1] - a[1]) / l1];
                let v = [(c[0] - b[0]) / l2, (c[1] - b[1]) / l2];
                let cross = difference_of_products(u[0], v[1], u[1], v[0]);
                let dot = difference_of_products(u[0], v[0], -u[1], v[1]);
                let turn = cross.atan2(dot);
                if !(turn > 0.0 && turn < PI) {
                    return refuse(format!(
                        "is not convex at point {} (counted from 0; rho = {}, z = {}): the meridian must turn one way, \
                         from the bottom pole up round the side to the top pole, and not run straight",
                        given(i),
                        crate::error::show(b[0]),
                        crate::error::show(b[1])
                    ));
                }
                // The inscribed angles at the neighbours: tan = sin t / (l₂/l₁ + cos t) at c
                // (the tangent less the chord in) and sin t / (l₁/l₂ + cos t) at a.
                before[i] = cross.atan2(l2 / l1 + dot);
                after[i] = cross.atan2(l1 / l2 + dot);
                chord_angle(a, b) + before[i]
            };
        }
        let straight = |i: usize| AtlasError::Profile {
            reason: format!(
                "has a straight side between the edges at points {} and {} (counted from 0; a \
                 cone's or a cylinder's side would lie flat on the plane); give points on a \
                 curved side or a flat face at a pole",
                given(i).min(given(i + 1)),
                given(i).max(given(i + 1))
            ),
        };
        // The tangents on either side of each edge: where the meridian arrives (one arc from
        // the smooth point before, whose chord is its middle direction; 0 past a bottom face
        // or at a bottom tip) and where it leaves (likewise to the point after; π before a
        // top face or at a top tip). Where the arcs would overshoot (the corner is weaker
        // than their turn) both take one tangent between the chords: the edge has no turn.
        let mut arrive = vec![f64::NAN; n];
        let mut leave = vec![f64::NAN; n];
        for i in (first..=last).filter(|&i| edge(i)) {
            let chord = |j: usize| chord_angle(at(j), at(j + 1));
            let bottom_fixed = i == 0 || (i == first && faces[0]);
            let top_fixed = i == n - 1 || (i == last && faces[1]);
            // (The chord in is the middle of the arc's turn: the tangent arrives as far beyond
            // it as the smooth point's left it behind.)
            arrive[i] = if bottom_fixed {
                0.0
            } else if edge(i - 1) {
                return Err(straight(i - 1));
            } else {
                before[i] = after[i - 1];
                2.0 * chord(i - 1) - tangent[i - 1]
            };
            leave[i] = if top_fixed {
                PI
            } else if edge(i + 1) {
                return Err(straight(i));
            } else {
                after[i] = before[i + 1];
                2.0 * chord(i) - tangent[i + 1]
            };
            // An edge whose turn is within rounding (a few ulps: a tip flag on a pole whose
            // neighbours lie on a circle through it) has none: a joint a few ulps from a pole
            // would split every integral there, and make the pole a tip.
            if arrive[i] > leave[i] || leave[i] - arrive[i] <= 64.0 * f64::EPSILON {
                let common = match (bottom_fixed, top_fixed) {
                    (true, _) => arrive[i],
                    (_, true) => leave[i],
                    _ => {
                        let (before, after) = (chord(i - 1), chord(i));
                        if after.partial_cmp(&before) != Some(std::cmp::Ordering::Greater) {
                            return refuse(format!(
                                "is not convex at the edge at point {} (counted from 0): the \
                                 meridian turns back there",
                                given(i)
                            ));
                        }
                        let margin = 0.25 * (after - before);
                        (0.5 * (arrive[i] + leave[i])).clamp(before + margin, after - margin)
                    }
                };
                arrive[i] = common;
                leave[i] = common;
                // (Past a bottom face or tip the chord out is the turn from 0 itself; before a
                // top one the chord in is π less its own.)
                if i > first {
                    before[i] = if top_fixed {
                        from_pi(at(i - 1), at(i))
                    } else {
                        common - chord(i - 1)
                    };
                }
                if i < last {
                    after[i] = if bottom_fixed {
                        chord(i)
                    } else {
                        chord(i) - common
                    };
                }
            }
        }
        let mut arcs: Vec<ProfileArc> = Vec::new();
        let push = |arcs: &mut Vec<ProfileArc>, arc: ProfileArc| {
            if arc.theta_end > arc.theta_start {
                arcs.push(arc);
            }
        };
        // The normal turns round an edge from where the meridian arrives to where it leaves
        // (arrive ≤ leave above; none where they are equal).
        let edge_arc = |i: usize| {
            ProfileArc::new(
                (arrive[i], leave[i], leave[i] - arrive[i]),
                0.0,
                arrive[i],
                at(i),
            )
        };
        for i in first..last {
            let (a, b) = (at(i), at(i + 1));
            let psi = chord_angle(a, b);
            let length = chord_length(a, b);
            let not_convex = |what: &str| AtlasError::Profile {
                reason: format!(
                    "is not convex between points {} and {} (counted from 0; {what}): the \
                     meridian must turn one way, from the bottom pole up round the side to the \
                     top pole",
                    given(i).min(given(i + 1)),
                    given(i).max(given(i + 1))
                ),
            };
            if edge(i) {
                push(&mut arcs, edge_arc(i));
            }
            let t0 = if edge(i) { leave[i] } else { tangent[i] };
            let t1 = if edge(i + 1) {
                arrive[i + 1]
            } else {
                tangent[i + 1]
            };
            // The chord less the tangent leaving a, and the tangent arriving at b less the chord.
            let (lead, lag) = (after[i], before[i + 1]);
            if !(lead > 0.0 && lag > 0.0 && lead + lag < PI && t0 < psi && psi < t1) {
                return Err(not_convex("the chord leaves the tangents' range"));
            }
            if lead == lag {
                // One arc: beside an edge whose tangent was taken from this chord.
                let radius = length / (2.0 * lead.sin());
                if !(radius.is_finite() && radius > 0.0) {
                    return Err(not_convex("no arc turning one way joins them"));
                }
                let anchor = if edge(i + 1) { (t0, a) } else { (t1, b) };
                push(
                    &mut arcs,
                    ProfileArc::new((t0, t1, lead + lag), radius, anchor.0, anchor.1),
                );
                continue;
            }
            // Two arcs (a biarc), the joint's tangent in the middle of the range where both
            // turn the same way as the meridian, [ψ − min, ψ + min] of the two offsets: the
            // chord ψ itself. The first turns `lead` over the chord c₁, the second `lag` over
            // c₂, the joint at c₁ = L sin(lag/2) / sin((lead + lag)/2) from a (and c₂ likewise)
            // on the chords' triangle with angles lead/2 and lag/2 at a and b.
            let det = (0.5 * (lead + lag)).sin();
            let c1 = length * (0.5 * lag).sin() / det;
            let c2 = length * (0.5 * lead).sin() / det;
            let r1 = c1 / (2.0 * (0.5 * lead).sin());
            let r2 = c2 / (2.0 * (0.5 * lag).sin());
            if !(r1.is_finite() && r2.is_finite() && r1 > 0.0 && r2 > 0.0) {
                return Err(not_convex("no two arcs turning one way join them"));
            }
            push(&mut arcs, ProfileArc::new((t0, psi, lead), r1, t0, a));
            push(&mut arcs, ProfileArc::new((psi, t1, lag), r2, t1, b));
        }
        if edge(last) {
            push(&mut arcs, edge_arc(last));
        }
        // The normal turns from 0 to π, never back.
        if arcs.first().map(|a| a.theta_start) != Some(0.0)
            || arcs.last().map(|a| a.theta_end) != Some(PI)
            || arcs.windows(2).any(|w| w[1].theta_start < w[0].theta_end)
        {
            return refuse(
                "is not convex: its normal does not turn once from the bottom pole to the top"
                    .into(),
            );
        }
        // The arcs meet where one ends; the next starts there (a biarc's two halves share
        // their joint's angle).
        for w in arcs.windows(2) {
            if w[1].theta_start != w[0].theta_end {
                return refuse("is not convex: two arcs overlap".into());
            }
        }
        let arcs = merge_arcs_of_one_circle(arcs);
        let joints: Vec<f64> = arcs[1..].iter().map(|a| a.theta_start).collect();
        let joint_sin_cos = joints.iter().map(|&j| libm::sincos(j)).collect();
        Ok(Self {
            points: rows,
            arcs,
            joints,
            joint_sin_cos,
            faces,
        })
    }

    /// The table, bottom pole first, as (ρ, z, edge).
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// The arcs and edges, in order of the normal angle from 0 to π.
    pub fn arcs(&self) -> &[ProfileArc] {
        &self.arcs
    }

    /// Whether a flat face ends the table at the bottom and at the top pole.
    pub fn faces(&self) -> [bool; 2] {
        self.faces
    }

    /// The heights z of the bottom and the top pole.
    pub fn poles(&self) -> [f64; 2] {
        [self.points[0][1], self.points[self.points.len() - 1][1]]
    }

    /// The profile's rows as text, one `rho z edge` a line (for files' attributes).
    pub fn text(&self) -> String {
        self.points
            .iter()
            .map(|p| format!("{:?} {:?} {}", p[0], p[1], p[2] as u8))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The arc in contact at the normal angle in [0, π] whose sine is `s` ≥ 0 and cosine `c`:
    /// past a joint j where sin(θ − j) = s cos j − c sin j ≥ 0 (θ and j in [0, π], the joints
    /// inside), which keeps its relative precision next to the joint, without an arctangent.
    #[inline]
    fn arc_at_sin_cos(&self, s: f64, c: f64) -> &ProfileArc {
        let past = |&(sj, cj): &(f64, f64)| s * cj - c * sj >= 0.0;
        &self.arcs[self.joint_sin_cos.partition_point(past)]
    }
}

/// The rows of a profile's table as text: one point a line, `rho z` or `rho z edge`, the
/// numbers separated by commas or by white space; empty lines and lines starting with `#` are
/// skipped, and so is a first line of column names (words only). Lines end at `\n`, `\r\n`
/// or `\r`. A line that is not a row of numbers, or a comma-separated line with an empty
/// field (which would shift the columns), is refused by its number.
pub fn parse_table(text: &str) -> Result<Vec<Vec<f64>>> {
    let mut rows = Vec::new();
    let mut first = true;
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let shown = || line.chars().take(60).collect::<String>();
        let words: Vec<&str> = if line.contains(',') {
            line.split(',').map(str::trim).collect()
        } else {
            line.split_whitespace().collect()
        };
        if words.iter().any(|w| w.is_empty()) {
            return refuse(format!(
                "has line {} with an empty field: {:?} (give every value)",
                i + 1,
                shown()
            ));
        }
        let numbers: std::result::Result<Vec<f64>, _> = words.iter().map(|w| w.parse()).collect();
        match numbers {
            Ok(row) => rows.push(row),
            // Column names on the first line.
            Err(_)
                if first
                    && words.iter().all(|w| {
                        w.parse::<f64>().is_err() && w.chars().any(char::is_alphabetic)
                    }) => {}
            Err(_) => {
                return refuse(format!(
                    "has line {} that is not a row of numbers: {:?}",
                    i + 1,
                    shown()
                ))
            }
        }
        first = false;
    }
    Ok(rows)
}

/// A body of the user's own profile, its centre of mass at height α on the axis in the
/// table's frame (strictly between the poles).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileShape {
    /// The meridian.
    pub profile: &'static Profile,
    /// α: the centre of mass at z = α on the axis, in the table's frame and unit.
    pub alpha: f64,
}

impl ProfileShape {
    /// The body of `profile` with its centre of mass at z = α, strictly between the poles.
    pub fn new(profile: &'static Profile, alpha: f64) -> Result<Self> {
        let [bottom, top] = profile.poles();
        if !(alpha > bottom && alpha < top) {
            return Err(AtlasError::InvalidParameter {
                name: "alpha",
                value: alpha,
                reason: "must lie strictly between the profile's poles (the centre of mass on the \
                         axis inside the body)",
            });
        }
        Ok(Self { profile, alpha })
    }

    /// The arc in contact at the angle `a` and (sin θ, cos θ) of the mirror angle in [0, π]
    /// (a body of revolution has U(−θ) = U(θ)).
    #[inline]
    fn arc(&self, a: Angle) -> (&ProfileArc, f64, f64) {
        let s = a.sin.abs();
        (self.profile.arc_at_sin_cos(s, a.cos), s, a.cos)
    }

    /// U, U′ (for sinθ ≥ 0) and U″ on one arc.
    #[inline]
    fn values(&self, arc: &ProfileArc, s: f64, c: f64) -> [f64; 3] {
        let (sin_d, cos_d) = arc.angle_from_anchor(s, c);
        let z = arc.anchor_z - self.alpha;
        let r = arc.radius;
        [
            arc.anchor_rho * s - z * c + r * one_minus_cos(sin_d, cos_d),
            arc.anchor_rho * c + z * s + r * sin_d,
            -arc.anchor_rho * s + z * c + r * cos_d,
        ]
    }

    /// The angle of a joint the angle `a` lies at, to a few ulps, with the arcs on either side.
    fn joint_at(&self, a: Angle) -> Option<usize> {
        let theta = a.sin.abs().atan2(a.cos);
        let i = self.profile.joints.partition_point(|&j| j < theta);
        [i.wrapping_sub(1), i].into_iter().find(|&k| {
            self.profile.joints.get(k).is_some_and(|&j| {
                // θ from the pair (sin, cos) is good to a few ulps of itself (atan2): near
                // θ = 0 relatively, elsewhere to a few ulps of π.
                (theta - j).abs() <= 16.0 * f64::EPSILON * j.max(theta).min(1.0)
            })
        })
    }
}

impl Shape for ProfileShape {
    fn kinks(&self) -> &[f64] {
        &self.profile.joints
    }

    /// 8 eps times the table's largest coordinate (or |α|): against U of the arc spline fitted
    /// anew at 50 digits (scripts/reference.py), the fitted arcs' U was within 2.9 eps of it at
    /// 14,400 random angles of 360 random tables (superellipses of 4 … 24 points, faces,
    /// α anywhere between the poles: `whole_domain.sample_profiles`, seeds 1 … 3). Where U is
    /// small (α 2e-6 below the top pole) that is far above U's own rounding: N = 14.7 of such
    /// a body was 7.4e-13 off at status `ok`, its estimate 1.4e-13, before this term.
    fn representation_error(&self) -> f64 {
        let largest = self
            .profile
            .points
            .iter()
            .map(|p| p[0].abs().max(p[1].abs()))
            .fold(self.alpha.abs(), f64::max);
        8.0 * f64::EPSILON * largest
    }

    /// Where a face ends the table: a flat circle on the plane at that pole.
    fn faces(&self) -> [bool; 2] {
        self.profile.faces
    }

    /// χ1 = −U − (U′/sinθ) cosθ, χ2 = U′/sinθ + χ1 cosθ (from U = −(χ1 sin²θ + χ2 cosθ) and
    /// U′ = sinθ (χ2 − χ1 cosθ)).
    fn chi(&self, theta: f64) -> (f64, f64) {
        let a = Angle::new(theta);
        let w = self.potential_prime_over_sin_at(a);
        let chi1 = -self.potential_at(a) - w * a.cos;
        (chi1, w + chi1 * a.cos)
    }

    /// The derivatives of [`ProfileShape::chi`], with w = U′/sinθ and
    /// w′ = (U″ sinθ − U′ cosθ)/sin²θ: χ1′ = −U′ − w′ cosθ + w sinθ, χ2′ = w′ + χ1′ cosθ − χ1 sinθ.
    fn chi_prime(&self, theta: f64) -> (f64, f64) {
        let a = Angle::new(theta);
        let (chi1, _) = self.chi(theta);
        let w = self.potential_prime_over_sin_at(a);
        let (up, upp) = (self.potential_prime_at(a), self.potential_second_at(a));
        let wp = (upp * a.sin - up * a.cos) / (a.sin * a.sin);
        let chi1p = -up - wp * a.cos + w * a.sin;
        (chi1p, wp + chi1p * a.cos - chi1 * a.sin)
    }

    /// On the arc in contact, with centre (ρ_c, z_c) and radius r: r = −r γ − ρ_c γ⊥/|γ⊥| +
    /// (z_c − α) e3, γ⊥ = (γ1, γ2, 0).
    fn contact_point(&self, gamma: &Vector3<f64>) -> Vector3<f64> {
        let s = gamma.x.hypot(gamma.y);
        let arc = self.profile.arc_at_sin_cos(s, gamma.z);
        let [rho_c, z_c] = arc.centre();
        let side = if s > 0.0 { rho_c / s } else { 0.0 };
        Vector3::new(
            -(arc.radius + side) * gamma.x,
            -(arc.radius + side) * gamma.y,
            -arc.radius * gamma.z + z_c - self.alpha,
        )
    }

    /// ṙ = −r γ̇ − ρ_c (ḣ/s − h (h, ḣ)/s³) with h = γ⊥, s = |h|.
    fn contact_point_rate(&self, gamma: &Vector3<f64>, gamma_dot: &Vector3<f64>) -> Vector3<f64> {
        let arc = self.profile.arc_at_sin_cos(gamma.x.hypot(gamma.y), gamma.z);
        let [rho_c, _] = arc.centre();
        -gamma_dot * arc.radius - super::horizontal_direction_rate(gamma, gamma_dot) * rho_c
    }

    theta_forms!(
        potential => potential_at,
        potential_prime => potential_prime_at,
        potential_second => potential_second_at,
        contact_distance_sq => contact_distance_sq_at,
    );

    /// d|r|²/dθ = 2U′(U + U″) = 2 r U′.
    fn contact_distance_sq_prime(&self, theta: f64) -> f64 {
        let a = Angle::new(theta);
        let (arc, s, c) = self.arc(a);
        2.0 * arc.radius * a.sin.signum() * self.values(arc, s, c)[1]
    }

    /// U = ρ_a sinθ − (z_a − α) cosθ + r (1 − cos(θ − θ_a)) on the arc in contact.
    #[inline]
    fn potential_at(&self, a: Angle) -> f64 {
        let (arc, s, c) = self.arc(a);
        self.values(arc, s, c)[0]
    }

    /// U′ = ρ_a cosθ + (z_a − α) sinθ + r sin(θ − θ_a) (odd in θ).
    #[inline]
    fn potential_prime_at(&self, a: Angle) -> f64 {
        let (arc, s, c) = self.arc(a);
        a.sin.signum() * self.values(arc, s, c)[1]
    }

    /// U″ = −ρ_a sinθ + (z_a − α) cosθ + r cos(θ − θ_a).
    #[inline]
    fn potential_second_at(&self, a: Angle) -> f64 {
        let (arc, s, c) = self.arc(a);
        self.values(arc, s, c)[2]
    }

    /// U′/sinθ = ρ_a cosθ/|sinθ| + (z_a − α) + r sin(θ − θ_a)/sinθ, the last r cos θ_a for an
    /// arc anchored at a pole (then sin(θ − θ_a) = sinθ cosθ_a exactly).
    #[inline]
    fn potential_prime_over_sin_at(&self, a: Angle) -> f64 {
        let (arc, s, c) = self.arc(a);
        let z = arc.anchor_z - self.alpha;
        let side = if arc.anchor_rho == 0.0 {
            0.0
        } else {
            arc.anchor_rho * c / s
        };
        // (An edge has r = 0: nothing to add, also at sinθ = 0 where the quotient is 0/0.)
        let turn = if arc.radius == 0.0 {
            0.0
        } else if arc.anchor_sin == 0.0 {
            arc.radius * arc.anchor_cos
        } else {
            arc.radius * arc.angle_from_anchor(s, c).0 / s
        };
        side + z + turn
    }

    #[inline]
    fn contact_distance_sq_at(&self, a: Angle) -> f64 {
        self.potential_and_contact_distance_sq_at(a).1
    }

    /// U and |r|² = U² + U′² from one lookup of the arc in contact.
    #[inline]
    fn potential_and_contact_distance_sq_at(&self, a: Angle) -> (f64, f64) {
        let (arc, s, c) = self.arc(a);
        let [u, up, _] = self.values(arc, s, c);
        (u, u * u + up * up)
    }

    /// (U(x) − U(y)) / sin(x − y) on one arc, without cancellation: with d = x − y and
    /// t = sin d/(1 + cos d), (sin x − sin y)/sin d = cos y − sin y t,
    /// (cos x − cos y)/sin d = −sin y − cos y t, and the same for x − θ_a, y − θ_a. An angle at
    /// a joint belongs to both arcs it joins; across a joint U is differenced directly.
    fn potential_divided_difference(
        &self,
        x: Angle,
        y: Angle,
        sin_diff: f64,
        cos_diff: f64,
    ) -> (f64, f64) {
        let direct = || super::subtracted_divided_difference(self, x, y, sin_diff);
        if !(x.sin * y.sin > 0.0 && cos_diff > -0.5) {
            return direct();
        }
        // Mirrored into [0, π] (U is even): the difference quotient changes sign.
        let sign = y.sin.signum();
        let (x, y) = (
            Angle {
                sin: x.sin.abs(),
                cos: x.cos,
            },
            Angle {
                sin: y.sin.abs(),
                cos: y.cos,
            },
        );
        let sin_diff = sign * sin_diff;
        let (ax, ay) = (self.arc(x).0, self.arc(y).0);
        let arc = if ax == ay {
            ay
        } else {
            let shared = |a: Angle, other: &ProfileArc| {
                self.joint_at(a).is_some_and(|k| {
                    let arcs = &self.profile.arcs[k..k + 2];
                    arcs.contains(other)
                })
            };
            if shared(y, ax) {
                ax
            } else if shared(x, ay) {
                ay
            } else {
                return direct();
            }
        };
        let t = sin_diff / (1.0 + cos_diff);
        let sin_dd = y.cos - y.sin * t;
        let cos_dd = -y.sin - y.cos * t;
        let (sin_v, cos_v) = arc.angle_from_anchor(y.sin, y.cos);
        let side = arc.anchor_rho * sin_dd;
        let height = -(arc.anchor_z - self.alpha) * cos_dd;
        let turn = arc.radius * (sin_v + cos_v * t);
        (
            sign * (side + height + turn),
            side.abs() + height.abs() + turn.abs(),
        )
    }

    fn potential_second_sides_at(&self, a: Angle) -> Option<[f64; 2]> {
        let k = self.joint_at(a)?;
        let s = a.sin.abs();
        let arcs = &self.profile.arcs[k..k + 2];
        Some([
            self.values(&arcs[0], s, a.cos)[2],
            self.values(&arcs[1], s, a.cos)[2],
        ])
    }

    /// U = ρ_a sinθ − (z_a − α) cosθ + r (1 − cos(θ − θ_a)) in double-double, the arc's numbers
    /// taken as exact (they are the body), with a bound of about 1e-30 of its terms.
    fn potential_double_double(
        &self,
        sin: DoubleDouble,
        cos: DoubleDouble,
    ) -> Option<(DoubleDouble, f64)> {
        let s = if sin.hi < 0.0 { sin.neg() } else { sin };
        let arc = self.profile.arc_at_sin_cos(s.hi, cos.hi);
        let z = DoubleDouble::from_f64(arc.anchor_z).sub(DoubleDouble::from_f64(self.alpha));
        let cos_d = cos.mul_f64(arc.anchor_cos).add(s.mul_f64(arc.anchor_sin));
        let turn = DoubleDouble::from_f64(1.0).sub(cos_d).mul_f64(arc.radius);
        let u = s.mul_f64(arc.anchor_rho).sub(z.mul(cos)).add(turn);
        let scale = arc.anchor_rho * s.hi + (z.hi * cos.hi).abs() + 2.0 * arc.radius;
        Some((u, crate::dd::RELATIVE_ERROR * scale))
    }

    /// Each arc is a sinusoid in θ, and integrals are split at the joints: no finer scale.
    fn angular_feature_scale(&self) -> f64 {
        1.0
    }

    /// On an arc U′ = ρ_a cosθ + (z_a − α) sinθ + r sin(θ − θ_a) = P cosθ + Q sinθ with
    /// P = ρ_a − r sin θ_a and Q = z_a − α + r cos θ_a: zero at θ = atan2(P, −Q) (mod π)
    /// where that lies on the arc.
    fn slope_zeros(&self) -> Vec<f64> {
        let mut zeros = Vec::new();
        for arc in self.profile.arcs() {
            let (sa, ca) = arc.anchor_theta.sin_cos();
            let p = arc.anchor_rho - arc.radius * sa;
            let q = arc.anchor_z - self.alpha + arc.radius * ca;
            if p == 0.0 && q == 0.0 {
                continue;
            }
            let root = p.atan2(-q);
            for theta in [
                root,
                root + std::f64::consts::PI,
                root - std::f64::consts::PI,
            ] {
                if theta > 0.0
                    && theta < std::f64::consts::PI
                    && theta >= arc.theta_start
                    && theta <= arc.theta_end
                {
                    zeros.push(theta);
                }
            }
        }
        zeros
    }
}
