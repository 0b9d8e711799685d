//! Aerofoil section coefficients for the blade-element lifting line: either the thin-aerofoil
//! fallback (`2 pi alpha`, no stall, no compressibility) or a C81 table (src/aero/c81.rs)
//! interpolated bilinearly in angle of attack and Mach number.
//!
//! Queries do not allocate (they run in the structural solver's hot loop). Queries outside a
//! table's range use the value at its edge, never an extrapolation, and are counted in a
//! [`ClampCounts`] shared between threads so that a run can report them.
use crate::aero::c81::{C81Table, Clamp};
use std::f64::consts::PI;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Lift, drag and pitching-moment coefficients of a section.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Coefficients {
    /// Lift coefficient.
    pub cl: f64,
    /// Drag coefficient.
    pub cd: f64,
    /// Pitching-moment coefficient.
    pub cm: f64,
}

/// Counts of queries clamped to a table's edges; thread-safe, share it through an `Arc`.
/// A query counts once per edge however many of cl, cd and cm clamped there.
#[derive(Debug, Default)]
pub struct ClampCounts {
    alpha_low: AtomicU64,
    alpha_high: AtomicU64,
    mach_low: AtomicU64,
    mach_high: AtomicU64,
    /// Every table query, clamped or not (the fraction's denominator); on a cache line of its
    /// own, as it is written on every query by every blade's thread.
    queries: Padded,
}

#[derive(Debug, Default)]
#[repr(align(64))]
struct Padded(AtomicU64);

impl ClampCounts {
    /// Counts one table query.
    fn query(&self) {
        self.queries.0.fetch_add(1, Ordering::Relaxed);
    }

    /// Table queries so far, clamped or not.
    pub fn queries(&self) -> u64 {
        self.queries.0.load(Ordering::Relaxed)
    }

    /// Queries clamped at any edge (a query clamped in alpha and Mach counts once per edge, so
    /// this may exceed [`Self::queries`] only by those).
    pub fn fraction_clamped(&self) -> f64 {
        self.total() as f64 / self.queries().max(1) as f64
    }

    /// Counts the edges of `clamp` (does nothing, and does not allocate, when none clamped).
    pub fn record(&self, clamp: Clamp) {
        if clamp.alpha_low {
            self.alpha_low.fetch_add(1, Ordering::Relaxed);
        }
        if clamp.alpha_high {
            self.alpha_high.fetch_add(1, Ordering::Relaxed);
        }
        if clamp.mach_low {
            self.mach_low.fetch_add(1, Ordering::Relaxed);
        }
        if clamp.mach_high {
            self.mach_high.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Queries below the table's angle-of-attack range.
    pub fn alpha_low(&self) -> u64 {
        self.alpha_low.load(Ordering::Relaxed)
    }

    /// Queries above the table's angle-of-attack range.
    pub fn alpha_high(&self) -> u64 {
        self.alpha_high.load(Ordering::Relaxed)
    }

    /// Queries below the table's Mach range.
    pub fn mach_low(&self) -> u64 {
        self.mach_low.load(Ordering::Relaxed)
    }

    /// Queries above the table's Mach range.
    pub fn mach_high(&self) -> u64 {
        self.mach_high.load(Ordering::Relaxed)
    }

    /// All clamped edges counted (a query clamped in alpha and Mach counts twice).
    pub fn total(&self) -> u64 {
        self.alpha_low() + self.alpha_high() + self.mach_low() + self.mach_high()
    }

    /// E.g. "12 queries below the table's angle-of-attack range, 3 above its Mach range";
    /// empty if nothing clamped. [`Airfoil::clamp_summary`] adds the table's limits.
    pub fn summary(&self) -> String {
        self.summary_with(None)
    }

    /// [`Self::summary`] with the tables' limits (see [`Airfoil::limits`]) in each part.
    pub fn summary_with(&self, limits: Option<[f64; 4]>) -> String {
        let lim = |k: usize, unit: &str, name: &str| match limits {
            Some(l) => format!(" ({name}{} {unit})", l[k]).replace(" )", ")"),
            None => String::new(),
        };
        let mut parts = Vec::new();
        let mut push = |n: u64, text: String| {
            if n > 0 {
                let q = if n == 1 { "query" } else { "queries" };
                parts.push(format!("{n} {q} {text}"));
            }
        };
        push(
            self.alpha_low(),
            format!(
                "below the table's angle of attack range{}",
                lim(0, "deg", "")
            ),
        );
        push(
            self.alpha_high(),
            format!(
                "above the table's angle of attack range{}",
                lim(1, "deg", "")
            ),
        );
        push(
            self.mach_low(),
            format!("below the table's Mach range{}", lim(2, "", "Mach ")),
        );
        push(
            self.mach_high(),
            format!("above the table's Mach range{}", lim(3, "", "Mach ")),
        );
        parts.join(", ")
    }
}

/// The thin-aerofoil fallback: `cl = a alpha`, constant `cd` and `cm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinAirfoil {
    /// Lift-curve slope a (1/rad), 2 pi by default.
    pub lift_slope_per_rad: f64,
    /// Drag coefficient, 0 by default.
    pub cd0: f64,
    /// Pitching-moment coefficient, 0 by default.
    pub cm0: f64,
}

impl Default for ThinAirfoil {
    fn default() -> Self {
        ThinAirfoil {
            lift_slope_per_rad: 2.0 * PI,
            cd0: 0.0,
            cm0: 0.0,
        }
    }
}

/// A section's aerofoil.
#[derive(Clone, Debug)]
pub enum Airfoil {
    /// The thin-aerofoil fallback.
    Thin(ThinAirfoil),
    /// A C81 table, shared between sections.
    Table(Arc<C81Table>),
}

/// `alpha` wrapped to [-pi, pi).
pub fn wrap_pi(alpha: f64) -> f64 {
    let two_pi = 2.0 * PI;
    let mut a = alpha - two_pi * ((alpha + PI) / two_pi).floor();
    if a >= PI {
        a -= two_pi;
    }
    if a < -PI {
        a = -PI;
    }
    a
}

impl Airfoil {
    /// Coefficients at angle of attack `alpha_rad` (any value; wrapped to [-pi, pi) first) and
    /// Mach number `mach` (>= 0).
    ///
    /// - Thin: the thin-aerofoil fallback "2 pi alpha, no stall, no compressibility":
    ///   `cl = a alpha`, `cd = cd0`, `cm = cm0`; Mach is ignored and nothing clamps. In reversed
    ///   flow (|alpha| > 90 deg) the plate meets the air trailing edge first: `cl = a (alpha -+
    ///   pi)`, the lift of a flat plate at that incidence (the lift is perpendicular to the
    ///   flow, so this is still upward for air from below).
    /// - Table: bilinear interpolation in (alpha in degrees, Mach) of each coefficient; outside
    ///   a table's alpha or Mach range the value at the edge is used and the matching counter
    ///   in `clamps` is incremented (once per query and edge).
    ///
    /// Does not allocate.
    pub fn coefficients(&self, alpha_rad: f64, mach: f64, clamps: &ClampCounts) -> Coefficients {
        let alpha = wrap_pi(alpha_rad);
        match self {
            Airfoil::Thin(t) => Coefficients {
                cl: t.lift_slope_per_rad * (alpha - PI * (alpha / PI).round()),
                cd: t.cd0,
                cm: t.cm0,
            },
            Airfoil::Table(t) => {
                let a = alpha.to_degrees();
                let (cl, c1) = t.cl.eval(a, mach);
                let (cd, c2) = t.cd.eval(a, mach);
                let (cm, c3) = t.cm.eval(a, mach);
                let clamp = c1.or(c2).or(c3);
                clamps.query();
                if clamp.any() {
                    clamps.record(clamp);
                }
                Coefficients { cl, cd, cm }
            }
        }
    }

    /// The aerofoil's name: the table's name, or "thin aerofoil (2 pi alpha)" with its slope.
    pub fn name(&self) -> String {
        match self {
            Airfoil::Thin(t) if t.lift_slope_per_rad == 2.0 * PI => {
                "thin aerofoil (2 pi alpha)".to_string()
            }
            Airfoil::Thin(t) => format!("thin aerofoil ({} alpha per rad)", t.lift_slope_per_rad),
            Airfoil::Table(t) => t.name.clone(),
        }
    }

    /// The limits beyond which a query clamps: [alpha low (deg), alpha high (deg), Mach low,
    /// Mach high], the narrowest over cl, cd and cm; `None` for the thin fallback.
    pub fn limits(&self) -> Option<[f64; 4]> {
        match self {
            Airfoil::Thin(_) => None,
            Airfoil::Table(t) => {
                let tabs = [&t.cl, &t.cd, &t.cm];
                let first = |v: &Vec<f64>| v[0];
                let last = |v: &Vec<f64>| v[v.len() - 1];
                Some([
                    tabs.iter()
                        .map(|x| first(&x.alpha_deg))
                        .fold(f64::MIN, f64::max),
                    tabs.iter()
                        .map(|x| last(&x.alpha_deg))
                        .fold(f64::MAX, f64::min),
                    tabs.iter().map(|x| first(&x.mach)).fold(f64::MIN, f64::max),
                    tabs.iter().map(|x| last(&x.mach)).fold(f64::MAX, f64::min),
                ])
            }
        }
    }

    /// The narrowest limits of `airfoils`' tables ([`Self::limits`]); `None` without a table.
    pub fn narrowest_limits<'a>(
        airfoils: impl IntoIterator<Item = &'a Airfoil>,
    ) -> Option<[f64; 4]> {
        airfoils
            .into_iter()
            .filter_map(Airfoil::limits)
            .reduce(|a, b| {
                [
                    a[0].max(b[0]),
                    a[1].min(b[1]),
                    a[2].max(b[2]),
                    a[3].min(b[3]),
                ]
            })
    }

    /// [`ClampCounts::summary`] with this aerofoil's limits, e.g. "3 queries above the table's
    /// Mach range (Mach 0.9)".
    pub fn clamp_summary(&self, clamps: &ClampCounts) -> String {
        clamps.summary_with(self.limits())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_to_minus_pi_pi() {
        assert_eq!(wrap_pi(0.25), 0.25);
        assert!((wrap_pi(0.25 + 2.0 * PI) - 0.25).abs() < 1e-12);
        assert!((wrap_pi(-0.25 - 4.0 * PI) + 0.25).abs() < 1e-12);
        assert_eq!(wrap_pi(PI), -PI);
        assert_eq!(wrap_pi(-PI), -PI);
        let a = wrap_pi(3.0 * PI - 1e-9);
        assert!((-PI..PI).contains(&a));
    }

    #[test]
    fn counts_and_summary() {
        let c = ClampCounts::default();
        assert_eq!(c.summary(), "");
        c.record(Clamp {
            alpha_low: true,
            mach_high: true,
            ..Clamp::default()
        });
        c.record(Clamp {
            mach_high: true,
            ..Clamp::default()
        });
        assert_eq!((c.alpha_low(), c.mach_high(), c.total()), (1, 2, 3));
        assert_eq!(
            c.summary(),
            "1 query below the table's angle of attack range, 2 queries above the table's Mach range"
        );
    }
}
