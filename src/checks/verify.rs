//! `rotorsim verify` as a library call: the verification suite of the structural solver (closed
//! forms, published benchmarks, conservation laws, mesh convergence), every check with its
//! reference, tolerance and verdict written to DIR/verify.json.
use crate::io::OutDir;
use crate::solver::verification::*;
use std::path::PathBuf;

/// The options of `rotorsim verify` besides its result folder: none today (clap and serde, so
/// that an option added later has one place).
#[derive(
    clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, Default, PartialEq, Eq,
)]
#[serde(default, deny_unknown_fields)]
pub struct VerifySettings {}

impl VerifySettings {
    /// The suite run into `out`.
    pub fn job(&self, out: impl Into<PathBuf>) -> VerifyJob {
        VerifyJob { out: out.into() }
    }
}

/// One run of the verification suite into its result folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VerifyJob {
    pub out: PathBuf,
}

/// Every check of the suite, in order.
#[derive(Clone, Debug)]
pub struct VerifyOutcome {
    pub entries: Vec<Entry>,
    /// verify.json.
    pub file: PathBuf,
}

impl VerifyOutcome {
    /// An error naming the count of failed checks, if any failed.
    pub fn verdict(&self) -> anyhow::Result<()> {
        let failed = self.entries.iter().filter(|e| !e.pass).count();
        if failed > 0 {
            anyhow::bail!(
                "{failed} verification checks failed (see {})",
                self.file.display()
            );
        }
        Ok(())
    }
}

/// One check of the suite with its verdict (an element of verify.json).
#[derive(serde::Serialize, Clone, Debug)]
pub struct Entry {
    #[serde(flatten)]
    pub check: Check,
    /// Tolerance on rel_error; null where the criterion is stated in `source` (observed order).
    pub tolerance: Option<f64>,
    pub pass: bool,
}

fn abs_check(case: &str, quantity: &str, computed: f64, source: &str) -> Check {
    // zero reference: rel_error holds the (already normalised) computed value
    Check {
        case: case.into(),
        quantity: quantity.into(),
        computed,
        reference: 0.0,
        rel_error: computed.abs(),
        source: source.into(),
    }
}

fn suite() -> Result<Vec<(Check, f64)>, String> {
    let mut out = vec![];
    // roll-up
    {
        let (l, ei) = (10.0, 100.0);
        let sec = uniform_section(1e6, 1e6, 100.0, ei, ei, 1.0, 0.02, 0.01, 0.01);
        let (mut m, tip, load) = cantilever(10, l, &sec);
        if let crate::structure::Element::Load(p) = &mut m.elements[load] {
            p.moment_nm = [0.0, 2.0 * std::f64::consts::PI * ei / l, 0.0];
        }
        let mut st = crate::solver::State::from_model(&m);
        let opts = crate::solver::StaticOptions {
            load_steps: 10,
            ..Default::default()
        };
        crate::solver::static_solve(&mut m, &mut st, &opts, |_, _, _, _| {})
            .map_err(|e| e.to_string())?;
        let x = st.x[tip];
        let d = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() / l;
        out.push((abs_check("rollup_M_2piEI_over_L", "tip_to_root_distance_over_L", d, "Simo & Vu-Quoc 1986, Comput. Methods Appl. Mech. Eng. 58:79 (tip returns to the root)"), 1e-6));
    }
    for (f, x, r) in bend45(8)? {
        for (k, c) in ["tip_x", "tip_y", "tip_z"].iter().enumerate() {
            out.push((
                Check::new(&format!("bend45_F{f}"), c, x[k], r[k], "Bathe & Bolourchi 1979 problem; reference tip positions of Simo & Vu-Quoc 1986 (8 linear elements; converged solutions differ by ~0.5)"),
                1.5e-2,
            ));
        }
    }
    for c in rotating_cantilever(8, &[0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0])? {
        out.push((c, 1e-3));
    }
    let (w, w_ref) = cantilever_release(8, 200, 6)?;
    out.push((Check::new("cantilever_release", "flap1_rad_s", w, w_ref, "Euler-Bernoulli cantilever 3.5160 sqrt(EI/mL^4); generalized-alpha rho_inf = 1, 200 steps per period"), 1e-3));
    let (e, p, l) = free_flying(1.0, 2000)?;
    let nrm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let de = e
        .iter()
        .map(|x| (x - e[0]).abs() / e[0])
        .fold(0.0, f64::max);
    let dp = p
        .iter()
        .map(|x| nrm([x[0] - p[0][0], x[1] - p[0][1], x[2] - p[0][2]]))
        .fold(0.0, f64::max)
        / nrm(p[0]);
    let dl = l
        .iter()
        .map(|x| nrm([x[0] - l[0][0], x[1] - l[0][1], x[2] - l[0][2]]))
        .fold(0.0, f64::max)
        / nrm(l[0]);
    let src = "conservation laws of the free beam (Simo & Vu-Quoc 1988 free-flying beam problem type), rho_inf = 1, 2000 steps of 0.01 s";
    out.push((
        abs_check("free_flying_beam", "max_rel_energy_change", de, src),
        1e-3,
    ));
    out.push((
        abs_check(
            "free_flying_beam",
            "max_rel_linear_momentum_change",
            dp,
            src,
        ),
        1e-10,
    ));
    out.push((
        abs_check(
            "free_flying_beam",
            "max_rel_angular_momentum_change",
            dl,
            src,
        ),
        1e-3,
    ));
    let (e, _, _) = free_flying(0.6, 1000)?;
    let grow = e.iter().map(|x| (x - e[0]) / e[0]).fold(f64::MIN, f64::max);
    out.push((
        abs_check(
            "free_flying_beam_rho0.6",
            "max_energy_above_initial_rel",
            grow.max(0.0),
            "energy must not exceed its initial value with numerical dissipation",
        ),
        1e-9,
    ));
    for (q, ns, errs, ord) in mesh_convergence()? {
        for (k, o) in ord.iter().enumerate() {
            out.push((
                Check {
                    case: format!("mesh_convergence {q}"),
                    quantity: format!("observed_order_{}_to_{}_elements", ns[k], ns[k + 1]),
                    computed: *o,
                    reference: 3.0,
                    rel_error: ((o - 3.0) / 3.0).abs(),
                    source: format!("self-convergence; reference = minimum order expected of cubic elements, pass if computed > 3; errors {}", errs.iter().map(|e| format!("{e:.3e}")).collect::<Vec<_>>().join(" ")),
                },
                f64::NAN,
            ));
        }
    }
    Ok(out)
}

impl VerifyJob {
    /// Runs every check and writes DIR/verify.json; failed checks are in the outcome
    /// ([`VerifyOutcome::verdict`]), a suite that cannot run is an error.
    pub fn execute(&self) -> anyhow::Result<VerifyOutcome> {
        let out = OutDir::create(&self.out, &[])?;
        let checks = match suite() {
            Ok(c) => c,
            Err(e) => {
                out.mark_incomplete(&format!("verification suite failed to run: {e}"))?;
                anyhow::bail!("verification suite failed to run: {e}");
            }
        };
        let entries: Vec<Entry> = checks
            .into_iter()
            .map(|(c, tol)| {
                let pass = if tol.is_nan() {
                    c.computed > 3.0
                } else {
                    c.rel_error <= tol
                };
                Entry {
                    tolerance: if tol.is_nan() { None } else { Some(tol) },
                    pass,
                    check: c,
                }
            })
            .collect();
        out.write(
            "verify.json",
            serde_json::to_string_pretty(&entries)?.as_bytes(),
        )?;
        out.finish()?;
        Ok(VerifyOutcome {
            entries,
            file: self.out.join("verify.json"),
        })
    }
}
