//! Fixed-frame hub loads of a rotor of N identical blades from one blade's root loads.
//!
//! On a periodic solution blade `b` (at azimuth `psi + 2 pi b / N`) carries at time `t` the
//! load blade 0 carries at `t + b T / N`, at the same place in the non-rotating frame, so its
//! root load in that frame is blade 0's, shifted. The hub load is the sum over the blades:
//! only harmonics that are multiples of N/rev survive (the others cancel between blades).

/// Rotating-frame components (x, y, z of a vector in the frame turned by `psi` about z)
/// into the non-rotating frame that coincides with it at `psi = 0`.
pub fn to_fixed(psi_rad: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = psi_rad.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

/// The sum over `n` blades of the fixed-frame signal `y` of blade 0, sampled at `y.len()`
/// equal steps over one revolution starting at azimuth 0: `sum_b y(psi + 2 pi b / n)`. When
/// the samples per revolution are a multiple of `n` the shift is a whole number of samples;
/// otherwise it is applied to the discrete Fourier series (exact for the sampled signal).
pub fn sum_of_blades(y: &[f64], n: usize) -> Vec<f64> {
    let m = y.len();
    if n == 0 || m == 0 {
        return vec![0.0; m];
    }
    if m.is_multiple_of(n) {
        let shift = m / n;
        return (0..m)
            .map(|i| (0..n).map(|b| y[(i + b * shift) % m]).sum())
            .collect();
    }
    // Fourier: keep the harmonics k that are multiples of n (times n)
    let tau = 2.0 * std::f64::consts::PI;
    let mut out = vec![0.0; m];
    for k in (0..=m / 2).filter(|k| k.is_multiple_of(n)) {
        let (mut a, mut b) = (0.0, 0.0);
        for (i, v) in y.iter().enumerate() {
            let ph = tau * (k * i) as f64 / m as f64;
            a += v * ph.cos();
            b += v * ph.sin();
        }
        let w = if k == 0 || 2 * k == m { 1.0 } else { 2.0 } / m as f64;
        for (i, o) in out.iter_mut().enumerate() {
            let ph = tau * (k * i) as f64 / m as f64;
            *o += n as f64 * w * (a * ph.cos() + b * ph.sin());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(m: usize) -> Vec<f64> {
        (0..m)
            .map(|i| {
                let p = 2.0 * std::f64::consts::PI * i as f64 / m as f64;
                (1..=9)
                    .map(|k| (k as f64 * p + 0.3 * k as f64).cos() / k as f64)
                    .sum::<f64>()
                    + 2.0
            })
            .collect()
    }

    #[test]
    fn only_multiples_of_n_per_rev_pass() {
        for m in [256, 250] {
            let y = signal(m);
            let h = sum_of_blades(&y, 4);
            // expected: 4 x (mean + the 4/rev and 8/rev terms)
            for (i, v) in h.iter().enumerate() {
                let p = 2.0 * std::f64::consts::PI * i as f64 / m as f64;
                let want = 4.0 * (2.0 + (4.0 * p + 1.2).cos() / 4.0 + (8.0 * p + 2.4).cos() / 8.0);
                assert!((v - want).abs() < 1e-12, "m {m} sample {i}: {v} vs {want}");
            }
        }
    }

    #[test]
    fn rotating_x_at_ninety_degrees_is_fixed_y() {
        let v = to_fixed(std::f64::consts::FRAC_PI_2, [1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
    }
}
