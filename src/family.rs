//! Families of tori: a name for each component of {V ≤ ε} that stays the same torus family
//! across the whole (κ, ε) plane and across bodies, and the layouts of an atlas's component
//! axis (by family, or by increasing θ_min).
//!
//! A component is labelled by the minima of V it encloses, named after the stable permanent
//! rotations of paper §4 (`s1`, `s2`, `s0`): the well of σ_s0 (θ < π/2), the well of σ_sπ
//! (θ > π/2), the equator σ_π/2 of a body symmetric about its equator, and at κ = 0 the
//! rolling over the top. A torus above a saddle, which encloses two wells, belongs to the
//! family of the well V keeps at large κ (σ_sπ for α > 0): that torus and the one round the
//! single well beyond the cusp κ_c are one family, with no bifurcation between them, so a
//! family is born or dies only on a critical curve (where the number of tori changes).

use serde::Serialize;

/// A family of invariant tori (the `family` flag of the files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// The well of a minimum of V at θ < π/2 (the symmetry axis within 90° of the upward
    /// vertical): the tori round the stable permanent rotations σ_s0, and at κ = 0 round
    /// the equilibrium σ0 (θ = 0).
    #[serde(rename = "well_0")]
    Well0 = 0,
    /// The well of a minimum at θ > π/2: the tori round σ_sπ, and at κ = 0 round the
    /// equilibrium σπ (θ = π) or the inclined equilibrium θ* of diagram type (a).
    WellPi = 1,
    /// The single well of V at θ = π/2 of a body symmetric about its equator (α = 0): the
    /// tori round the rolling on the equator σ_π/2.
    WellEquator = 2,
    /// κ = 0 and ε above the top of U: rolling over the top along a meridian.
    OverTheTop = 3,
    /// A second torus on the side θ < π/2, round a shallower well than `well_0`'s (an
    /// edged body's, e.g. a profile's; the ellipsoid has at most one well a side).
    #[serde(rename = "well_0_second")]
    Well0Second = 4,
    /// A second torus on the side θ > π/2, round a shallower well than `well_pi`'s.
    WellPiSecond = 5,
}

impl Family {
    /// Every family, in code order.
    pub const ALL: [Family; 6] = [
        Family::Well0,
        Family::WellPi,
        Family::WellEquator,
        Family::OverTheTop,
        Family::Well0Second,
        Family::WellPiSecond,
    ];
    /// The families of a body with at most one well on each side of the equator (the
    /// ellipsoid), in code order.
    pub const ONE_WELL_A_SIDE: [Family; 4] = [
        Family::Well0,
        Family::WellPi,
        Family::WellEquator,
        Family::OverTheTop,
    ];
    /// The codes, as the files' `flag_values`.
    pub const VALUES: [u8; 6] = [0, 1, 2, 3, 4, 5];
    /// The names, as the files' `flag_meanings`.
    pub const MEANINGS: &'static str =
        "well_0 well_pi well_equator over_the_top well_0_second well_pi_second";

    /// The families a body of `kind` (None: the ellipsoid) can have: the ellipsoid has at
    /// most one well on each side of the equator (paper §4); an edged body's wells are not
    /// told in advance (a profile may have two on one side).
    pub fn possible_for(kind: Option<&crate::EdgedKind>) -> &'static [Family] {
        match kind {
            None => &Family::ONE_WELL_A_SIDE,
            Some(_) => &Family::ALL,
        }
    }

    /// Which families (by code) are among `families`.
    pub fn mask(families: &[Family]) -> [bool; Family::ALL.len()] {
        let mut mask = [false; Family::ALL.len()];
        for f in families {
            mask[usize::from(f.code())] = true;
        }
        mask
    }

    /// The family's code in the files.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The family's name (`well_0`, …), as in the files' `flag_meanings` and the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Family::Well0 => "well_0",
            Family::WellPi => "well_pi",
            Family::WellEquator => "well_equator",
            Family::OverTheTop => "over_the_top",
            Family::Well0Second => "well_0_second",
            Family::WellPiSecond => "well_pi_second",
        }
    }

    /// The family of a code.
    pub fn from_code(code: u8) -> Option<Family> {
        Family::ALL.get(usize::from(code)).copied()
    }

    /// The family of a name.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which side of the equator θ = π/2 a minimum of V lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// θ < π/2 (on the κ = 0 circle: within π/2 of θ = 0).
    Upper,
    /// θ > π/2 (on the circle: within π/2 of θ = π).
    Lower,
    /// At θ = π/2 on a body symmetric about its equator.
    Equator,
}

/// The family of a libration or fixed point whose wells lie on `sides` (one entry per
/// minimum of V it encloses): the family of its side when they lie on one, else `outer`,
/// the family of the well V keeps at large κ (a torus above a saddle).
pub fn of_sides(sides: impl IntoIterator<Item = Side>, outer: Family) -> Option<Family> {
    let (mut upper, mut lower, mut equator) = (false, false, false);
    for side in sides {
        match side {
            Side::Upper => upper = true,
            Side::Lower => lower = true,
            Side::Equator => equator = true,
        }
    }
    Some(match (upper, lower, equator) {
        (false, false, false) => return None,
        (true, false, false) => Family::Well0,
        (false, true, false) => Family::WellPi,
        (false, false, true) => Family::WellEquator,
        _ => outer,
    })
}

/// Tells apart the tori of one side's family in one cell (a profile may have two wells on a
/// side): `families[i]` is component i's family by [`of_sides`], `depths[i]` the value of
/// V at its deepest well. The torus round the deepest well of the side keeps `well_0` /
/// `well_pi`; the others become `well_0_second` / `well_pi_second`. So the family goes on
/// through the level where a shallow well (an edge's, say) opens beside the main one, and
/// changes hands only where the two wells' depths cross. Mirror images at κ = 0 (equal
/// depths, to within rounding) keep one family. A third torus on one side is a second
/// `…_second` (the family layout then keeps one of them and marks the cell failed).
pub fn rank_by_depth(families: &mut [Family], depths: &[f64]) {
    for (main, second) in [
        (Family::Well0, Family::Well0Second),
        (Family::WellPi, Family::WellPiSecond),
    ] {
        let deepest = families
            .iter()
            .zip(depths)
            .filter(|(f, _)| **f == main)
            .map(|(_, &v)| v)
            .fold(f64::INFINITY, f64::min);
        // Depths closer than this are one well seen twice (a mirror pair at κ = 0).
        let same = 1e-9 * deepest.abs().max(1.0);
        for (f, &v) in families.iter_mut().zip(depths) {
            if *f == main && v > deepest + same {
                *f = second;
            }
        }
    }
}

/// How the component axis of an atlas is laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// Slot k holds one family in every cell: the coordinate `component` is the family's
    /// code (the default).
    #[default]
    Family,
    /// Slot k holds the k-th component in increasing θ_min.
    ThetaMin,
}

impl Layout {
    /// Every layout's name, for messages.
    pub const NAMES: &'static str = "\"family\" or \"theta_min\"";

    /// The layout's name, as in scenes and the files' `component_layout`.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Family => "family",
            Layout::ThetaMin => "theta_min",
        }
    }

    /// The layout of a name.
    pub fn from_name(name: &str) -> Option<Layout> {
        match name {
            "family" => Some(Layout::Family),
            "theta_min" => Some(Layout::ThetaMin),
            _ => None,
        }
    }
}

/// What a set of cells holds, enough to lay out its component axis: the families present
/// and the most components any one cell has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Census {
    /// Whether each family (by code) occurs.
    pub families: [bool; Family::ALL.len()],
    /// The most components in one cell.
    pub most: usize,
}

impl Census {
    /// Adds one cell's families (its components in θ_min order).
    pub fn add(&mut self, families: &[Family]) {
        for f in families {
            self.families[usize::from(f.code())] = true;
        }
        self.most = self.most.max(families.len());
    }

    /// The census of two sets of cells together.
    pub fn merge(mut self, other: Census) -> Census {
        for (a, b) in self.families.iter_mut().zip(other.families) {
            *a |= b;
        }
        self.most = self.most.max(other.most);
        self
    }
}

/// The families an ellipsoid (α, β) can have anywhere on its (κ, ε) plane: a superset read
/// off its diagram type (paper §4). For κ ≠ 0 a second well (σ_s0 beside σ_sπ, or its mirror
/// for α < 0) exists only in type (c), β² > 1 + |α| (type (e) for α = 0, β > 1); the single
/// well of a body symmetric about its equator is `well_equator`. Cells at κ = 0 may have any
/// family (the equilibria, θ*, rolling over the top, the degenerate sphere): with
/// `kappa_zero` every family is possible. The boundary β² = 1 + |α| is widened by a margin,
/// so that rounding never leaves out a family: a superset only costs the census its early
/// end.
pub fn possible_for_ellipsoid(
    alpha: f64,
    beta: f64,
    kappa_zero: bool,
) -> [bool; Family::ALL.len()] {
    if kappa_zero {
        return Family::mask(&Family::ONE_WELL_A_SIDE);
    }
    let mut possible = [false; Family::ALL.len()];
    let two_wells = beta * beta > (1.0 + alpha.abs()) * (1.0 - 1e-6);
    let mut allow = |f: Family| possible[usize::from(f.code())] = true;
    if alpha == 0.0 {
        allow(Family::WellEquator);
        if two_wells {
            allow(Family::Well0);
            allow(Family::WellPi);
        }
    } else {
        // The well V keeps at large κ, on the side U descends to at π/2 (U′(π/2) = −α).
        allow(if alpha > 0.0 {
            Family::WellPi
        } else {
            Family::Well0
        });
        if two_wells {
            allow(Family::Well0);
            allow(Family::WellPi);
        }
    }
    possible
}

impl Census {
    /// Whether this census has found every family `possible` allows (and so can end).
    pub fn covers(&self, possible: &[bool; Family::ALL.len()]) -> bool {
        self.families
            .iter()
            .zip(possible)
            .all(|(&found, &allowed)| found || !allowed)
    }
}

/// The labels of an atlas's component axis: the family codes present (layout `Family`) or
/// 0, 1, … (layout `ThetaMin`). A grid without motion anywhere keeps one slot, labelled
/// [`crate::atlas::FLAG_FILL`] in the family layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ComponentAxis {
    pub layout: Layout,
    pub labels: Vec<u8>,
}

impl ComponentAxis {
    /// The axis for cells of this census: no slot is empty in every cell.
    pub fn of(layout: Layout, census: &Census) -> ComponentAxis {
        let labels: Vec<u8> = match layout {
            Layout::Family => Family::ALL
                .into_iter()
                .filter(|f| census.families[usize::from(f.code())])
                .map(Family::code)
                .collect(),
            Layout::ThetaMin => (0..census.most.min(usize::from(u8::MAX)) as u8).collect(),
        };
        let labels = if labels.is_empty() {
            vec![match layout {
                Layout::Family => crate::atlas::FLAG_FILL,
                Layout::ThetaMin => 0,
            }]
        } else {
            labels
        };
        ComponentAxis { layout, labels }
    }

    /// Room for any cell of a body that can have `families`: each of them, or `slots`
    /// components by θ_min.
    pub fn full(layout: Layout, families: &[Family], slots: usize) -> ComponentAxis {
        let census = Census {
            families: Family::mask(families),
            most: slots,
        };
        ComponentAxis::of(layout, &census)
    }

    /// Slots per cell.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether the axis has no slot (never: it keeps one).
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// The slot of the component `index` (in θ_min order) of family `family`, if the axis
    /// has one for it.
    pub fn slot(&self, index: usize, family: Family) -> Option<usize> {
        match self.layout {
            Layout::Family => self.labels.iter().position(|&c| c == family.code()),
            Layout::ThetaMin => (index < self.labels.len()).then_some(index),
        }
    }

    /// The CF `flag_values` and `flag_meanings` of the coordinate `component` in the family
    /// layout (None in the θ_min layout).
    pub fn flag_attributes(&self) -> Option<(Vec<u8>, String)> {
        (self.layout == Layout::Family).then(|| {
            let names: Vec<&str> = self
                .labels
                .iter()
                .map(|&c| {
                    Family::from_code(c).map_or(crate::atlas::FLAG_FILL_MEANING, Family::name)
                })
                .collect();
            (self.labels.clone(), names.join(" "))
        })
    }
}
