//! Load recovery from a structural solution: section loads of beams, loads at cuts through
//! nodes, resultants of applied and inertial loads on a set of bodies, and the fixed-frame
//! sum of N identical blades (docs/loads.md).
//!
//! Section loads are recovered by nodal equilibrium, not from the constitutive law at the
//! Gauss points: the load just outboard of an element's first node is minus that element's
//! whole residual there (elastic, dissipative, inertial and applied parts), which is exactly
//! the resultant of everything the discrete model applies outboard (joint reactions
//! included), because the weak form holds for rigid virtual motions element by element.
//! Inside an element the loads follow by integrating the element's own load densities (its
//! four inertia points, interpolated by the cubic through them) from that node, so a
//! polynomial load up to degree 3 gives exact section loads anywhere. The constitutive
//! resultants at the three reduced-integration points would carry the discretisation error
//! of the strains instead.
//!
//! The module knows no rotor: callers name elements and nodes.
pub mod hub;

use crate::solver::State;
use crate::structure::beam::{shape, Beam, Interp, PointDensity, NPTS_M};
use crate::structure::kin::{EvalCtx, NodeKin};
use crate::structure::model::{Element, Model};
use crate::structure::rotation::*;

/// A force and a moment (global components; the moment about a stated point).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Resultant {
    pub force: [f64; 3],
    pub moment: [f64; 3],
}

impl Resultant {
    /// The same load with its moment taken about `to` instead of `from`.
    pub fn moved(&self, from: [f64; 3], to: [f64; 3]) -> Resultant {
        Resultant {
            force: self.force,
            moment: add(self.moment, cross(sub(from, to), self.force)),
        }
    }
    pub fn add(&self, o: &Resultant) -> Resultant {
        Resultant {
            force: add(self.force, o.force),
            moment: add(self.moment, o.moment),
        }
    }
    /// Components in the frame whose columns are `r`.
    pub fn in_frame(&self, r: &M3<f64>) -> Resultant {
        Resultant {
            force: mtv(r, self.force),
            moment: mtv(r, self.moment),
        }
    }
}

/// Loads at a beam section: what the outboard part (larger arc length) exerts on the inboard
/// part, global components, the moment about `point`; `frame` the section frame (columns e1
/// along the axis, e2, e3).
#[derive(Clone, Copy, Debug)]
pub struct Section {
    pub point: [f64; 3],
    pub frame: M3<f64>,
    pub load: Resultant,
}

/// The six section-frame components a loads engineer reads (docs/loads.md, sign
/// conventions).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SectionComponents {
    /// Along e1, tension positive [N].
    pub axial_n: f64,
    /// Along e2 (chord, toward the leading edge) [N].
    pub shear_chord_n: f64,
    /// Along e3 (normal to the chord, up at zero pitch) [N].
    pub shear_flap_n: f64,
    /// About e1, nose up positive [N m].
    pub torsion_nm: f64,
    /// Tip-up bending positive (minus the moment about e2) [N m].
    pub flap_nm: f64,
    /// Bending toward the leading edge positive (the moment about e3) [N m].
    pub chord_nm: f64,
}

impl Section {
    /// The section's pitch about its own axis e1 relative to the plane normal to `up` (a
    /// unit vector; the shaft axis for a blade) [rad], nose up positive: the angle
    /// `atan2(e2 . up, e3 . up)` by which the section frame is turned about e1 from the frame
    /// whose second axis lies in that plane (docs/loads.md, "unpitched blade frame"). For a
    /// frame `Rz(-zeta) Ry(-beta) Rx(theta)` of the plane's axes it is theta, whatever the
    /// lag zeta and flap beta.
    pub fn pitch_about(&self, up: [f64; 3]) -> f64 {
        let f = &self.frame;
        let e2 = [f[0][1], f[1][1], f[2][1]];
        let e3 = [f[0][2], f[1][2], f[2][2]];
        dot(e2, up).atan2(dot(e3, up))
    }

    /// The components in the unpitched blade frame: the section frame turned back about e1
    /// by [`Section::pitch_about`] `up`, so that its second axis lies in the plane normal to
    /// `up` (docs/loads.md).
    pub fn unpitched_components(&self, up: [f64; 3]) -> SectionComponents {
        self.components().turned_back(self.pitch_about(up))
    }

    pub fn components(&self) -> SectionComponents {
        let l = self.load.in_frame(&self.frame);
        SectionComponents {
            axial_n: l.force[0],
            shear_chord_n: l.force[1],
            shear_flap_n: l.force[2],
            torsion_nm: l.moment[0],
            flap_nm: -l.moment[1],
            chord_nm: l.moment[2],
        }
    }
}

impl SectionComponents {
    /// The same load in the frame turned by `-theta` about e1 (e1' = e1,
    /// e2' = cos(theta) e2 - sin(theta) e3, e3' = sin(theta) e2 + cos(theta) e3): a section
    /// pitched nose up by theta seen from the frame without that pitch. Axial force and
    /// torsion are unchanged.
    pub fn turned_back(&self, theta: f64) -> SectionComponents {
        let (s, c) = theta.sin_cos();
        SectionComponents {
            axial_n: self.axial_n,
            shear_chord_n: c * self.shear_chord_n - s * self.shear_flap_n,
            shear_flap_n: s * self.shear_chord_n + c * self.shear_flap_n,
            torsion_nm: self.torsion_nm,
            // flap = -M . e2, chord = M . e3
            flap_nm: c * self.flap_nm + s * self.chord_nm,
            chord_nm: c * self.chord_nm - s * self.flap_nm,
        }
    }
}

/// Why a load could not be recovered (a caller's wiring error, not input).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LoadsError {
    #[error("element {0} is not a beam")]
    NotABeam(usize),
    #[error("arc length {s_m} m is outside element {elem} ({lo} .. {hi} m)")]
    OutsideElement {
        elem: usize,
        s_m: f64,
        lo: f64,
        hi: f64,
    },
    #[error("element {elem} does not act on node {node}")]
    NotOnNode { elem: usize, node: usize },
    #[error("element {0} does not exist")]
    NoElement(usize),
}

fn beam_kin(b: &Beam, st: &State) -> [NodeKin<f64>; 4] {
    b.nodes.map(|i| st.node_kin(i))
}

/// First multiplier of every element in the state's `lambda` (model element order).
pub fn lambda_offsets(model: &Model) -> Vec<usize> {
    let mut o = Vec::with_capacity(model.elements.len());
    let mut n = 0;
    for e in &model.elements {
        o.push(n);
        n += e.n_lambda();
    }
    o
}

/// Loads just outboard of reference arc length `s_m` of beam element `elem` (see the module
/// documentation). `lam_off` from [`lambda_offsets`] is not needed: beams have none.
pub fn section(
    model: &Model,
    st: &State,
    ctx: &EvalCtx,
    elem: usize,
    s_m: f64,
) -> Result<Section, LoadsError> {
    let Some(Element::Beam(b)) = model.elements.get(elem) else {
        return Err(if elem < model.elements.len() {
            LoadsError::NotABeam(elem)
        } else {
            LoadsError::NoElement(elem)
        });
    };
    let [s0, s1] = b.s_range;
    let tol = 1e-9 * (s1 - s0);
    if !(s0 - tol..=s1 + tol).contains(&s_m) {
        return Err(LoadsError::OutsideElement {
            elem,
            s_m,
            lo: s0,
            hi: s1,
        });
    }
    let k = beam_kin(b, st);
    let ip = b.interp(&k);
    let d = b.densities_with(&k, &ip.rg, ctx);
    Ok(section_from(b, &k, &ip, &d, s_m))
}

/// [`section`] from the element's configuration `k`, its interpolation and its densities
/// (computed once when several loads of one element are wanted); `s_m` within the element.
pub fn section_from(
    b: &Beam,
    k: &[NodeKin<f64>; 4],
    ip: &Interp,
    d: &[PointDensity; NPTS_M],
    s_m: f64,
) -> Section {
    let [s0, s1] = b.s_range;
    let tol = 1e-9 * (s1 - s0);
    let (r, point, frame) = b.recovery(k, ip, d, s_m);
    // just outboard of node 0: minus the element's residual there
    let f0 = [-r[0], -r[1], -r[2]];
    let m0 = [-r[3], -r[4], -r[5]];
    let mut load = Resultant {
        force: f0,
        moment: m0,
    }
    .moved(k[0].x, point);
    let len = s_m - s0;
    if len > tol {
        // + int_{s0}^{s} (inertial - applied) densities, moments about the section point
        let sq: [f64; NPTS_M] = d.map(|p| p.s_m);
        for (p, w) in GAUSS4_X.iter().zip(&GAUSS4_W) {
            let s = s0 + 0.5 * len * (p + 1.0);
            let wt = 0.5 * len * w;
            let l = lagrange(&sq, s);
            let mut f = [0.0; 3];
            let mut m = [0.0; 3];
            for q in 0..NPTS_M {
                f = add(f, fmul(l[q], d[q].force_n_per_m));
                m = add(m, fmul(l[q], d[q].moment_nm_per_m));
            }
            let xi = -1.0 + 2.0 * (s - s0) / (s1 - s0);
            let (n, _) = shape(xi);
            let mut x = [0.0; 3];
            for i in 0..4 {
                x = add(x, fmul(n[i], k[i].x));
            }
            load.force = add(load.force, fmul(wt, f));
            load.moment = add(load.moment, fmul(wt, add(cross(sub(x, point), f), m)));
        }
    }
    Section { point, frame, load }
}

/// The element of beam `beam` (model element ids in order along it) holding reference arc
/// length `s_m`, the outboard one at an element boundary (the last one at the end).
pub fn element_at(model: &Model, beam: &[usize], s_m: f64) -> Option<usize> {
    let range = |e: usize| match &model.elements[e] {
        Element::Beam(b) => Some(b.s_range),
        _ => None,
    };
    let last = *beam.last()?;
    for &e in beam {
        let [s0, s1] = range(e)?;
        let tol = 1e-9 * (s1 - s0);
        if s_m >= s0 - tol && s_m < s1 - tol {
            return Some(e);
        }
    }
    let [s0, s1] = range(last)?;
    (s_m <= s1 + 1e-9 * (s1 - s0) && s_m >= s0).then_some(last)
}

/// 4-point Gauss-Legendre rule on [-1, 1] (exact to degree 7: a cubic load density times a
/// cubic lever arm), as constants: the recovery runs every sample and must not allocate.
const GAUSS4_X: [f64; 4] = [
    -0.861_136_311_594_052_6,
    -0.339_981_043_584_856_26,
    0.339_981_043_584_856_26,
    0.861_136_311_594_052_6,
];
const GAUSS4_W: [f64; 4] = [
    0.347_854_845_137_453_85,
    0.652_145_154_862_546_1,
    0.652_145_154_862_546_1,
    0.347_854_845_137_453_85,
];

/// Lagrange basis through the points `s` evaluated at `x`.
fn lagrange(s: &[f64; NPTS_M], x: f64) -> [f64; NPTS_M] {
    std::array::from_fn(|i| {
        let mut v = 1.0;
        for j in 0..NPTS_M {
            if j != i {
                v *= (x - s[j]) / (s[i] - s[j]);
            }
        }
        v
    })
}

/// The load element `elem` exerts on node `node` (minus its residual there; joints with their
/// multipliers from `st.lambda`), the moment about the node. `lam_off` from
/// [`lambda_offsets`].
pub fn element_on_node(
    model: &Model,
    st: &State,
    ctx: &EvalCtx,
    lam_off: &[usize],
    elem: usize,
    node: usize,
) -> Result<Resultant, LoadsError> {
    let e = model
        .elements
        .get(elem)
        .ok_or(LoadsError::NoElement(elem))?;
    let mut r = [0.0; 24];
    let local = match e {
        Element::Beam(b) => {
            let l = b.nodes.iter().position(|&n| n == node);
            if l.is_some() {
                b.residual_f64(&beam_kin(b, st), ctx, &mut r);
            }
            l
        }
        Element::Rigid(b) => {
            (b.node == node).then(|| b.residual(&st.node_kin(node), ctx, &mut r));
            (b.node == node).then_some(0)
        }
        Element::Load(l) => {
            (l.node == node).then(|| l.residual(&st.node_kin(node), ctx, &mut r));
            (l.node == node).then_some(0)
        }
        Element::Joint(j) => {
            let lam = &st.lambda[lam_off[elem]..lam_off[elem] + j.n_lambda()];
            let ctx1 = EvalCtx {
                cscale: 1.0,
                ..*ctx
            };
            let b = st.node_kin(j.node_b);
            match j.node_a {
                Some(a) => {
                    let l = if a == node {
                        Some(0)
                    } else if j.node_b == node {
                        Some(1)
                    } else {
                        None
                    };
                    if l.is_some() {
                        j.residual_f64(&st.node_kin(a), &b, lam, &ctx1, &mut r);
                    }
                    l
                }
                None => {
                    let l = (j.node_b == node).then_some(0);
                    if l.is_some() {
                        j.residual_f64(&NodeKin::ground(), &b, lam, &ctx1, &mut r);
                    }
                    l
                }
            }
        }
    };
    let l = local.ok_or(LoadsError::NotOnNode { elem, node })?;
    Ok(Resultant {
        force: [-r[6 * l], -r[6 * l + 1], -r[6 * l + 2]],
        moment: [-r[6 * l + 3], -r[6 * l + 4], -r[6 * l + 5]],
    })
}

/// Applied minus inertial load of one element's densities (its quadrature), the moment about
/// `about`.
pub fn densities_resultant(d: &[PointDensity; NPTS_M], about: [f64; 3]) -> Resultant {
    let mut out = Resultant::default();
    for p in d {
        let f = fmul(-p.weight_m, p.force_n_per_m);
        let m = fmul(-p.weight_m, p.moment_nm_per_m);
        out.force = add(out.force, f);
        out.moment = add(out.moment, add(m, cross(sub(p.x, about), f)));
    }
    out
}

/// Applied minus inertial loads of the beams and rigid bodies `elems` (gravity included),
/// the moment about `about`: what those bodies receive besides the forces of the elements
/// joined to them.
pub fn applied_and_inertial(
    model: &Model,
    st: &State,
    ctx: &EvalCtx,
    elems: &[usize],
    about: [f64; 3],
) -> Result<Resultant, LoadsError> {
    let mut out = Resultant::default();
    for &ei in elems {
        match model.elements.get(ei).ok_or(LoadsError::NoElement(ei))? {
            Element::Beam(b) => {
                out = out.add(&densities_resultant(
                    &b.point_densities(&beam_kin(b, st), ctx),
                    about,
                ));
            }
            Element::Rigid(b) => {
                let mut r = [0.0; 6];
                let k = st.node_kin(b.node);
                b.residual(&k, ctx, &mut r);
                let l = Resultant {
                    force: [-r[0], -r[1], -r[2]],
                    moment: [-r[3], -r[4], -r[5]],
                };
                out = out.add(&l.moved(k.x, about));
            }
            Element::Load(p) => {
                let mut r = [0.0; 6];
                let k = st.node_kin(p.node);
                p.residual(&k, ctx, &mut r);
                let l = Resultant {
                    force: [-r[0], -r[1], -r[2]],
                    moment: [-r[3], -r[4], -r[5]],
                };
                out = out.add(&l.moved(k.x, about));
            }
            Element::Joint(_) => return Err(LoadsError::NotABeam(ei)),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_a_moment_adds_the_lever_arm() {
        let r = Resultant {
            force: [0.0, 0.0, 10.0],
            moment: [0.0; 3],
        };
        // a vertical force at x = 2 has a moment -20 about y at the origin
        let m = r.moved([2.0, 0.0, 0.0], [0.0; 3]);
        assert_eq!(m.moment, [0.0, -20.0, 0.0]);
    }

    #[test]
    fn gauss_constants_are_the_four_point_rule() {
        let (x, w) = crate::structure::beam::gauss(4);
        for i in 0..4 {
            assert!((x[i] - GAUSS4_X[i]).abs() < 1e-15 && (w[i] - GAUSS4_W[i]).abs() < 1e-15);
        }
    }

    #[test]
    fn lagrange_basis_interpolates_a_cubic_exactly() {
        let s = [0.1, 0.35, 0.7, 0.95];
        let f = |x: f64| 1.0 - 2.0 * x + 0.5 * x * x - 3.0 * x * x * x;
        let x = 0.42;
        let l = lagrange(&s, x);
        let v: f64 = (0..4).map(|i| l[i] * f(s[i])).sum();
        assert!((v - f(x)).abs() < 1e-14);
    }
}
