//! Mode labels solved jointly: the eigenvalues of one block of the Coleman equations are
//! assigned to the block's families (regressing lag, airframe x, ...) at once, so that each
//! family is used by one conjugate pair (or by one overdamped pair of real roots) per block.
//!
//! Each eigenvalue offers each family its share of the eigenvector's kinetic energy
//! ([`shares`]); the assignment maximises the total share over the block (a best-total-weight
//! assignment, Hungarian algorithm). A complex eigenvalue and its conjugate go to one family
//! together; real roots go two by two, every pairing of them tried.
use super::lag_rotor::ModeLabel;
use faer::c64;

/// Real roots of a block beyond which their pairings are not all tried (then consecutive by
/// growth rate); 8 real roots have 105 pairings.
const MAX_PAIRED_REALS: usize = 8;

/// A family of a block and how many conjugate pairs (or pairs of real roots) it takes: one per
/// coordinate it stands for (two per coordinate pair for the cyclic lag, split into
/// regressing and progressive).
#[derive(Clone, Copy, Debug)]
pub(super) struct Family {
    pub label: ModeLabel,
    pub slots: usize,
}

/// `energy` scaled to sum 1 (all zero when it has no energy).
pub(super) fn shares(energy: &[f64]) -> Vec<f64> {
    let total: f64 = energy.iter().sum();
    if total > 0.0 && total.is_finite() {
        energy.iter().map(|e| e / total).collect()
    } else {
        vec![0.0; energy.len()]
    }
}

/// The cyclic share `cyclic` of the eigenvalue `lam` split into (regressing, progressive) by
/// the whirl of its cyclic coordinates `(zc, zs)` (of the `Im >= 0` member): a mode is
/// progressive when its whirl turns forward in the rotating frame, i.e. forward whirl in the
/// fixed frame at a fixed-frame frequency above `omega`. The forward part of the whirl above
/// `omega` goes to the progressive family, the rest to the regressing one.
pub(super) fn whirl_split(lam: c64, zc: c64, zs: c64, omega: f64, cyclic: f64) -> (f64, f64) {
    let iz = c64::new(-zs.im, zs.re);
    let (fwd, bwd) = ((zc + iz).norm().powi(2), (zc - iz).norm().powi(2));
    let forward = if lam.im.abs() > omega && fwd + bwd > 0.0 {
        fwd / (fwd + bwd)
    } else {
        0.0
    };
    (cyclic * (1.0 - forward), cyclic * forward)
}

/// The label of each of `lams` (all eigenvalues of a block, conjugates included), from
/// `weights[j][f]`, the share of eigenvalue `j` in `families[f]`. When the eigenvalues do not
/// fill the families' slots exactly (not expected), each takes its best family.
pub(super) fn assign(lams: &[c64], weights: &[Vec<f64>], families: &[Family]) -> Vec<ModeLabel> {
    let best_each = || {
        weights
            .iter()
            .map(|w| {
                (0..families.len())
                    .max_by(|&a, &b| w[a].total_cmp(&w[b]).then(b.cmp(&a)))
                    .map_or(ModeLabel::Unresolved, |f| families[f].label)
            })
            .collect()
    };
    // the conjugate pairs (upper member first) and the real roots
    let mut pairs: Vec<(usize, usize)> = vec![];
    let mut lower: Vec<usize> = (0..lams.len()).filter(|&j| lams[j].im < 0.0).collect();
    let mut reals: Vec<usize> = (0..lams.len()).filter(|&j| lams[j].im == 0.0).collect();
    for j in (0..lams.len()).filter(|&j| lams[j].im > 0.0) {
        let near = (0..lower.len()).min_by(|&a, &b| {
            (lams[lower[a]] - lams[j].conj())
                .norm()
                .total_cmp(&(lams[lower[b]] - lams[j].conj()).norm())
        });
        match near {
            Some(k) => pairs.push((j, lower.swap_remove(k))),
            None => return best_each(),
        }
    }
    if !lower.is_empty() {
        return best_each();
    }
    let slots: Vec<usize> = families
        .iter()
        .enumerate()
        .flat_map(|(f, fam)| std::iter::repeat_n(f, fam.slots))
        .collect();
    if !reals.len().is_multiple_of(2) || pairs.len() + reals.len() / 2 != slots.len() {
        return best_each();
    }
    // reals by decreasing growth rate (the fallback pairs neighbours)
    reals.sort_by(|&a, &b| lams[b].re.total_cmp(&lams[a].re).then(a.cmp(&b)));
    let pairings = if reals.len() <= MAX_PAIRED_REALS {
        perfect_matchings(&reals)
    } else {
        vec![reals.chunks(2).map(|c| (c[0], c[1])).collect()]
    };
    // (total share, units, slot of each unit)
    type Choice = (f64, Vec<(usize, usize)>, Vec<usize>);
    let mut best: Option<Choice> = None;
    for real_pairs in pairings {
        let units: Vec<(usize, usize)> = pairs.iter().chain(&real_pairs).copied().collect();
        let gain = |u: usize, s: usize| {
            let (a, b) = units[u];
            weights[a][slots[s]] + weights[b][slots[s]]
        };
        let n = units.len();
        let cost: Vec<Vec<f64>> = (0..n)
            .map(|u| (0..n).map(|s| -gain(u, s)).collect())
            .collect();
        let of_unit = hungarian(&cost);
        let total: f64 = (0..n).map(|u| gain(u, of_unit[u])).sum();
        if best.as_ref().is_none_or(|b| total > b.0 + 1e-12) {
            best = Some((total, units, of_unit));
        }
    }
    let Some((_, units, of_unit)) = best else {
        return best_each();
    };
    let mut of_unit = of_unit;
    whirls_by_frequency(lams, weights, &units, &slots, families, &mut of_unit);
    let mut out = vec![ModeLabel::Unresolved; lams.len()];
    for (u, &(a, b)) in units.iter().enumerate() {
        let label = families[slots[of_unit[u]]].label;
        out[a] = label;
        out[b] = label;
    }
    out
}

/// An airframe with the same properties in x and y whirls: its modes have equal x and y
/// shares, and which of two of them is "x" is the eigen-solver's rounding. Two units holding
/// `AirframeX` and `AirframeY` whose exchange changes the total share by less than [`TIE`]
/// are ordered by frequency: the lower takes `AirframeX`.
fn whirls_by_frequency(
    lams: &[c64],
    weights: &[Vec<f64>],
    units: &[(usize, usize)],
    slots: &[usize],
    families: &[Family],
    of_unit: &mut [usize],
) {
    let fam = |u: usize, of: &[usize]| families[slots[of[u]]].label;
    let gain = |u: usize, s: usize| {
        let (a, b) = units[u];
        weights[a][slots[s]] + weights[b][slots[s]]
    };
    let freq = |u: usize| lams[units[u].0].im.abs();
    for u in 0..units.len() {
        for v in 0..units.len() {
            if !(fam(u, of_unit) == ModeLabel::AirframeY
                && fam(v, of_unit) == ModeLabel::AirframeX
                && freq(u) < freq(v))
            {
                continue;
            }
            let (su, sv) = (of_unit[u], of_unit[v]);
            let kept = gain(u, su) + gain(v, sv);
            let swapped = gain(u, sv) + gain(v, su);
            if (kept - swapped).abs() < TIE {
                of_unit.swap(u, v);
            }
        }
    }
}

/// Total shares closer than this are a tie (equal x and y shares of a whirling airframe).
const TIE: f64 = 1e-6;

/// Every way of pairing the (even number of) `items`.
fn perfect_matchings(items: &[usize]) -> Vec<Vec<(usize, usize)>> {
    let Some((&first, rest)) = items.split_first() else {
        return vec![vec![]];
    };
    let mut out = vec![];
    for k in 0..rest.len() {
        let mut others = rest.to_vec();
        let partner = others.remove(k);
        for mut m in perfect_matchings(&others) {
            m.insert(0, (first, partner));
            out.push(m);
        }
    }
    out
}

/// The least-cost assignment of the square `cost` (rows to columns): the column of each row
/// (Hungarian algorithm with potentials, O(n^3)).
fn hungarian(cost: &[Vec<f64>]) -> Vec<usize> {
    let n = cost.len();
    // 1-based: p[j] the row on column j, 0 none
    let (mut u, mut v) = (vec![0.0; n + 1], vec![0.0; n + 1]);
    let (mut p, mut way) = (vec![0usize; n + 1], vec![0usize; n + 1]);
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0;
        let mut minv = vec![f64::INFINITY; n + 1];
        let mut used = vec![false; n + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0;
            for j in 1..=n {
                if !used[j] {
                    let cur = cost[i0 - 1][j - 1] - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=n {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut of_row = vec![0; n];
    for j in 1..=n {
        if p[j] > 0 {
            of_row[p[j] - 1] = j - 1;
        }
    }
    of_row
}

/// The number of each mode within its family at one speed (`modes` as labels and
/// eigenvalues): 0 for a family's only mode; else 1, 2, ... by decreasing growth rate (the
/// least damped first), then by frequency.
pub(super) fn roots_within_family(modes: &[(ModeLabel, c64)]) -> Vec<usize> {
    let mut out = vec![0; modes.len()];
    for (i, (label, _)) in modes.iter().enumerate() {
        let mut same: Vec<usize> = (0..modes.len()).filter(|&k| modes[k].0 == *label).collect();
        if same.len() < 2 {
            continue;
        }
        same.sort_by(|&a, &b| {
            let (la, lb) = (modes[a].1, modes[b].1);
            lb.re
                .total_cmp(&la.re)
                .then(la.im.abs().total_cmp(&lb.im.abs()))
                .then(a.cmp(&b))
        });
        out[i] = same.iter().position(|&k| k == i).unwrap_or(0) + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hungarian_finds_the_least_total_cost() {
        let cost = vec![
            vec![4.0, 1.0, 3.0],
            vec![2.0, 0.0, 5.0],
            vec![3.0, 2.0, 2.0],
        ];
        let a = hungarian(&cost);
        let total: f64 = (0..3).map(|i| cost[i][a[i]]).sum();
        assert_eq!(total, 5.0, "{a:?}");
    }

    #[test]
    fn two_modes_that_both_prefer_one_family_share_them_out() {
        let fam = |label| Family { label, slots: 1 };
        let families = [fam(ModeLabel::RegressingLag), fam(ModeLabel::AirframeX)];
        let l = |re: f64, im: f64| c64::new(re, im);
        let lams = [l(0.1, 10.0), l(0.1, -10.0), l(-0.2, 11.0), l(-0.2, -11.0)];
        let w = |a: f64| vec![a, 1.0 - a];
        let weights = [w(0.6), w(0.6), w(0.55), w(0.55)];
        let labels = assign(&lams, &weights, &families);
        assert_eq!(labels[0], ModeLabel::RegressingLag);
        assert_eq!(labels[1], ModeLabel::RegressingLag);
        assert_eq!(labels[2], ModeLabel::AirframeX);
        assert_eq!(labels[3], ModeLabel::AirframeX);
    }

    #[test]
    fn an_overdamped_pair_takes_one_family_and_is_numbered() {
        let fam = |label| Family { label, slots: 1 };
        let families = [fam(ModeLabel::RegressingLag), fam(ModeLabel::AirframeY)];
        let l = |re: f64, im: f64| c64::new(re, im);
        let lams = [l(-0.1, 0.0), l(-0.3, 10.0), l(-3.0, 0.0), l(-0.3, -10.0)];
        let weights = [
            vec![0.1, 0.9],
            vec![0.9, 0.1],
            vec![0.3, 0.7],
            vec![0.9, 0.1],
        ];
        let labels = assign(&lams, &weights, &families);
        assert_eq!(
            labels,
            [
                ModeLabel::AirframeY,
                ModeLabel::RegressingLag,
                ModeLabel::AirframeY,
                ModeLabel::RegressingLag
            ]
        );
        let modes: Vec<(ModeLabel, c64)> =
            [0, 1, 2].iter().map(|&j| (labels[j], lams[j])).collect();
        assert_eq!(roots_within_family(&modes), [1, 0, 2]);
    }
}
