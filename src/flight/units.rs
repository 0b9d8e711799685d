//! Units at the edges: CSV column names carry the unit; values are converted to SI on reading.
//!
//! Accepted units (docs/formats.md, plus the UH-60A airloads database's non-dimensional form):
//! - normal and chord force per span: `N_per_m`, `lb_per_in`, `M2Cn` / `M2Cc`
//! - pitching moment per span: `N_m_per_m`, `in_lb_per_in`, `M2Cm`
//! - damper force: `N`, `lb`; damper stroke: `m`, `in`
//!
//! The non-dimensional airloads are M^2 c_n = N' / (1/2 rho a^2 c), M^2 c_c = C' / (1/2 rho a^2 c),
//! M^2 c_m = M' / (1/2 rho a^2 c^2), with density `density_kg_m3`, speed of sound
//! `speed_of_sound_m_s` and chord `chord_m` from the record's metadata.

/// International avoirdupois pound-force [N] (exact by definition).
pub const LBF_N: f64 = 4.448_221_615_260_5;
/// Inch [m] (exact by definition).
pub const INCH_M: f64 = 0.0254;

/// The quantity a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    NormalForce,
    ChordForce,
    PitchingMoment,
    DamperForce,
    DamperStroke,
}

impl Quantity {
    /// Column prefix (the part of the column name before the unit).
    pub fn prefix(self) -> &'static str {
        match self {
            Quantity::NormalForce => "normal_force_",
            Quantity::ChordForce => "chord_force_",
            Quantity::PitchingMoment => "pitching_moment_",
            Quantity::DamperForce => "damper_force_",
            Quantity::DamperStroke => "damper_stroke_",
        }
    }

    /// Column name in SI (what rotorsim writes).
    pub fn si_column(self) -> &'static str {
        match self {
            Quantity::NormalForce => "normal_force_N_per_m",
            Quantity::ChordForce => "chord_force_N_per_m",
            Quantity::PitchingMoment => "pitching_moment_N_m_per_m",
            Quantity::DamperForce => "damper_force_N",
            Quantity::DamperStroke => "damper_stroke_m",
        }
    }

    /// Accepted unit suffixes, SI first.
    pub fn units(self) -> &'static [&'static str] {
        match self {
            Quantity::NormalForce => &["N_per_m", "lb_per_in", "M2Cn"],
            Quantity::ChordForce => &["N_per_m", "lb_per_in", "M2Cc"],
            Quantity::PitchingMoment => &["N_m_per_m", "in_lb_per_in", "M2Cm"],
            Quantity::DamperForce => &["N", "lb"],
            Quantity::DamperStroke => &["m", "in"],
        }
    }
}

/// A unit of one column, as a conversion to SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unit {
    /// Already SI.
    Si,
    /// Multiply by this factor to get SI.
    Factor(f64),
    /// Non-dimensional M^2 C: multiply by 1/2 rho a^2 c (forces) or 1/2 rho a^2 c^2 (moment);
    /// the factor is known only once the metadata is read.
    MachSquaredCoefficient,
}

impl Unit {
    /// Conversion factor to SI, given the dynamic-pressure scale `q_c` = 1/2 rho a^2 c [N/m] and
    /// the chord [m] (needed only for [`Unit::MachSquaredCoefficient`]).
    pub fn factor(self, quantity: Quantity, q_c: f64, chord_m: f64) -> f64 {
        match self {
            Unit::Si => 1.0,
            Unit::Factor(f) => f,
            Unit::MachSquaredCoefficient => match quantity {
                Quantity::PitchingMoment => q_c * chord_m,
                _ => q_c,
            },
        }
    }
}

/// Parses the unit suffix of a column of `quantity`. `None` for an unknown unit.
pub fn parse_unit(quantity: Quantity, suffix: &str) -> Option<Unit> {
    match (quantity, suffix) {
        (Quantity::NormalForce | Quantity::ChordForce, "N_per_m") => Some(Unit::Si),
        (Quantity::NormalForce | Quantity::ChordForce, "lb_per_in") => {
            Some(Unit::Factor(LBF_N / INCH_M))
        }
        (Quantity::NormalForce, "M2Cn") | (Quantity::ChordForce, "M2Cc") => {
            Some(Unit::MachSquaredCoefficient)
        }
        (Quantity::PitchingMoment, "N_m_per_m") => Some(Unit::Si),
        // in-lb per inch of span = lb.
        (Quantity::PitchingMoment, "in_lb_per_in") => Some(Unit::Factor(LBF_N)),
        (Quantity::PitchingMoment, "M2Cm") => Some(Unit::MachSquaredCoefficient),
        (Quantity::DamperForce, "N") => Some(Unit::Si),
        (Quantity::DamperForce, "lb") => Some(Unit::Factor(LBF_N)),
        (Quantity::DamperStroke, "m") => Some(Unit::Si),
        (Quantity::DamperStroke, "in") => Some(Unit::Factor(INCH_M)),
        _ => None,
    }
}

/// Splits a column name into its quantity and unit suffix; bare `M2Cn`, `M2Cc`, `M2Cm` (the
/// UH-60A database's names) are accepted as the non-dimensional airloads.
pub fn split_column(name: &str) -> Option<(Quantity, &str)> {
    match name {
        "M2Cn" => return Some((Quantity::NormalForce, "M2Cn")),
        "M2Cc" => return Some((Quantity::ChordForce, "M2Cc")),
        "M2Cm" => return Some((Quantity::PitchingMoment, "M2Cm")),
        _ => {}
    }
    [
        Quantity::NormalForce,
        Quantity::ChordForce,
        Quantity::PitchingMoment,
        Quantity::DamperForce,
        Quantity::DamperStroke,
    ]
    .into_iter()
    .find_map(|q| name.strip_prefix(q.prefix()).map(|u| (q, u)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imperial_factors() {
        // 1 lb/in = 175.1268... N/m; 1 in-lb/in = 1 lb = 4.448... N m/m.
        let f = parse_unit(Quantity::NormalForce, "lb_per_in").unwrap();
        approx::assert_relative_eq!(
            f.factor(Quantity::NormalForce, 0.0, 0.0),
            175.126_835_246_476_4,
            max_relative = 1e-15
        );
        let m = parse_unit(Quantity::PitchingMoment, "in_lb_per_in").unwrap();
        assert_eq!(m.factor(Quantity::PitchingMoment, 0.0, 0.0), LBF_N);
        let s = parse_unit(Quantity::DamperStroke, "in").unwrap();
        assert_eq!(s.factor(Quantity::DamperStroke, 0.0, 0.0), 0.0254);
    }

    #[test]
    fn mach_squared_coefficient_scales() {
        // q_c = 1/2 rho a^2 c; the moment takes one more chord.
        let (rho, a, c) = (1.0, 336.0, 0.527);
        let q_c = 0.5 * rho * a * a * c;
        let u = parse_unit(Quantity::PitchingMoment, "M2Cm").unwrap();
        assert_eq!(u.factor(Quantity::PitchingMoment, q_c, c), q_c * c);
        let u = parse_unit(Quantity::NormalForce, "M2Cn").unwrap();
        assert_eq!(u.factor(Quantity::NormalForce, q_c, c), q_c);
        assert!(parse_unit(Quantity::ChordForce, "M2Cn").is_none());
    }

    #[test]
    fn column_split_and_unknown_units() {
        assert_eq!(
            split_column("normal_force_kN_per_m"),
            Some((Quantity::NormalForce, "kN_per_m"))
        );
        assert!(parse_unit(Quantity::NormalForce, "kN_per_m").is_none());
        assert_eq!(split_column("M2Cc"), Some((Quantity::ChordForce, "M2Cc")));
        assert_eq!(split_column("temperature_K"), None);
        assert_eq!(Quantity::DamperForce.units(), &["N", "lb"]);
    }
}
