//! The CF metadata every file of the program shares: units that UDUNITS parses, with the
//! scale of the paper's dimensionless quantities stated in a `comment`, and root attribute
//! values. One place, so that an atlas, a table and a Python Dataset name and scale a
//! quantity alike.

/// The conventions the files follow (the `Conventions` root attribute): CF-1.11, whose
/// data types include the unsigned bytes of the flags (CF-1.8 has none).
pub const CONVENTIONS: &str = "CF-1.11";

/// The units of a quantity: a UDUNITS string and, for the paper's scaled quantities, the
/// `comment` that states the scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Units {
    pub units: &'static str,
    pub comment: Option<&'static str>,
}

/// A pure number (counts, indices, ratios, the rotation number).
pub const NUMBER: Units = Units {
    units: "1",
    comment: None,
};

/// An angle in radians.
pub const ANGLE: Units = Units {
    units: "rad",
    comment: None,
};

/// A length, in units of b3 (the semi-axis along the symmetry axis).
pub const LENGTH: Units = Units {
    units: "1",
    comment: Some("dimensionless: a length in units of b3, the semi-axis along the symmetry axis"),
};

/// A time, in units of √(b3/g).
pub const TIME: Units = Units {
    units: "1",
    comment: Some("dimensionless: a time in units of sqrt(b3/g)"),
};

/// An angular rate, in radians per unit of time √(b3/g).
pub const RATE: Units = Units {
    units: "1",
    comment: Some("dimensionless: an angular rate in radians per unit of time sqrt(b3/g)"),
};

/// An energy, in units of m g b3.
pub const ENERGY: Units = Units {
    units: "1",
    comment: Some("dimensionless: an energy in units of m g b3"),
};

/// A quantity in the paper's units (κ = F2, λ = κ/√ε, s = 1/√ε).
pub const PAPER: Units = Units {
    units: "1",
    comment: Some(
        "dimensionless: in the paper's units, in which the mass m, the length b3 and the \
         time sqrt(b3/g) are 1",
    ),
};

/// A root attribute value: numbers stay numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum AttrValue {
    Text(String),
    Number(f64),
    Integer(i64),
}

impl AttrValue {
    /// The value as a CSV comment or a line of text shows it.
    pub fn display(&self) -> String {
        match self {
            AttrValue::Text(t) => t.clone(),
            AttrValue::Number(x) => format!("{x:e}"),
            AttrValue::Integer(i) => i.to_string(),
        }
    }
}

/// The current UTC time as ISO 8601 with seconds (`2026-11-22T23:54:04Z`).
pub fn utc_now() -> String {
    jiff::Timestamp::now()
        .round(jiff::Unit::Second)
        .map(|t| t.to_string())
        .unwrap_or_default()
}

/// The CF `history` line of a file made now by `command`: the time, then the command.
pub fn history(command: &str) -> String {
    format!("{}: {}", utc_now(), command)
}
