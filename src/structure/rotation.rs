//! Finite rotations: generic 3-vectors/3x3 matrices, exponential and logarithm maps, tangent
//! operators. Nodes store unit quaternions; increments are rotation vectors applied on the left
//! (spatial): `R <- exp(theta~) R`.
use super::real::{c, Real};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

pub type V3<T> = [T; 3];
pub type M3<T> = [[T; 3]; 3];

#[inline]
pub fn v3c<T: Real>(a: &[f64; 3]) -> V3<T> {
    [c(a[0]), c(a[1]), c(a[2])]
}
#[inline]
pub fn m3c<T: Real>(a: &[[f64; 3]; 3]) -> M3<T> {
    [v3c(&a[0]), v3c(&a[1]), v3c(&a[2])]
}
#[inline]
pub fn zero3<T: Real>() -> V3<T> {
    [c(0.0); 3]
}
#[inline]
pub fn add<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub fn sub<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub fn smul<T: Real>(s: T, a: V3<T>) -> V3<T> {
    [s * a[0], s * a[1], s * a[2]]
}
#[inline]
pub fn fmul<T: Real>(s: f64, a: V3<T>) -> V3<T> {
    [a[0].scale(s), a[1].scale(s), a[2].scale(s)]
}
#[inline]
pub fn dot<T: Real>(a: V3<T>, b: V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// Euclidean length of a 3-vector.
#[inline]
pub fn norm3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
#[inline]
pub fn cross<T: Real>(a: V3<T>, b: V3<T>) -> V3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub fn mv<T: Real>(m: &M3<T>, v: V3<T>) -> V3<T> {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
/// `m^T v`
#[inline]
pub fn mtv<T: Real>(m: &M3<T>, v: V3<T>) -> V3<T> {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}
#[inline]
pub fn mm<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    let mut r = [[c(0.0); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    r
}
/// `a^T b`
#[inline]
pub fn mtm<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    let mut r = [[c(0.0); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j];
        }
    }
    r
}
#[inline]
pub fn transpose<T: Real>(a: &M3<T>) -> M3<T> {
    let mut r = *a;
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[j][i];
        }
    }
    r
}
#[inline]
pub fn skew<T: Real>(v: V3<T>) -> M3<T> {
    let z = c(0.0);
    [[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]]
}
#[inline]
pub fn ident<T: Real>() -> M3<T> {
    let (o, z) = (c(1.0), c(0.0));
    [[o, z, z], [z, o, z], [z, z, o]]
}
#[inline]
pub fn madd<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    let mut r = *a;
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] += b[i][j];
        }
    }
    r
}
#[inline]
pub fn mscale<T: Real>(s: T, a: &M3<T>) -> M3<T> {
    let mut r = *a;
    for row in r.iter_mut() {
        for x in row.iter_mut() {
            *x = s * *x;
        }
    }
    r
}

/// Coefficients `(sin t / t, (1 - cos t) / t^2, (t - sin t) / t^3)` as smooth functions of
/// `t^2` (series near zero so that dual parts stay exact at the identity).
#[inline]
pub fn rot_coeffs<T: Real>(t2: T) -> (T, T, T) {
    if t2.re() < 1e-6 {
        let a = c::<T>(1.0) - t2 * (c::<T>(1.0 / 6.0) - t2 * c(1.0 / 120.0));
        let b = c::<T>(0.5) - t2 * (c::<T>(1.0 / 24.0) - t2 * c(1.0 / 720.0));
        let cc = c::<T>(1.0 / 6.0) - t2 * (c::<T>(1.0 / 120.0) - t2 * c(1.0 / 5040.0));
        (a, b, cc)
    } else {
        let t = t2.sqrt();
        let (s, co) = (t.sin(), t.cos());
        (s / t, (c::<T>(1.0) - co) / t2, (t - s) / (t2 * t))
    }
}

/// Exponential map `exp(theta~) = I + a theta~ + b theta~^2`.
pub fn exp_map<T: Real>(th: V3<T>) -> M3<T> {
    let (a, b, _) = rot_coeffs(dot(th, th));
    let k = skew(th);
    let k2 = mm(&k, &k);
    madd(&madd(&ident(), &mscale(a, &k)), &mscale(b, &k2))
}

/// Right tangent operator: `exp(psi)^T d exp(psi) = (T_R(psi) d psi)~`,
/// `T_R = I - b psi~ + c psi~^2`.
pub fn tangent_right<T: Real>(p: V3<T>) -> M3<T> {
    let (_, b, cc) = rot_coeffs(dot(p, p));
    let k = skew(p);
    let k2 = mm(&k, &k);
    madd(&madd(&ident(), &mscale(-b, &k)), &mscale(cc, &k2))
}

/// Left tangent operator: `d exp(psi) exp(psi)^T = (T_L(psi) d psi)~`, `T_L = T_R^T`.
pub fn tangent_left<T: Real>(p: V3<T>) -> M3<T> {
    transpose(&tangent_right(p))
}

/// Logarithm map (rotation vector with angle in [0, pi]) via the quaternion (Shepperd).
pub fn log_map<T: Real>(r: &M3<T>) -> V3<T> {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let trr = tr.re();
    let (w, v) = if trr >= r[0][0].re() && trr >= r[1][1].re() && trr >= r[2][2].re() {
        let w = (c::<T>(1.0) + tr).sqrt().scale(0.5);
        let f = c::<T>(0.25) / w;
        (
            w,
            [
                (r[2][1] - r[1][2]) * f,
                (r[0][2] - r[2][0]) * f,
                (r[1][0] - r[0][1]) * f,
            ],
        )
    } else {
        let i = if r[0][0].re() >= r[1][1].re() && r[0][0].re() >= r[2][2].re() {
            0
        } else if r[1][1].re() >= r[2][2].re() {
            1
        } else {
            2
        };
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let vi = (c::<T>(1.0) + r[i][i] + r[i][i] - tr).sqrt().scale(0.5);
        let f = c::<T>(0.25) / vi;
        let mut v = [c(0.0); 3];
        v[i] = vi;
        v[j] = (r[j][i] + r[i][j]) * f;
        v[k] = (r[k][i] + r[i][k]) * f;
        let w = (r[k][j] - r[j][k]) * f;
        (w, v)
    };
    let (w, v) = if w.re() < 0.0 {
        (-w, [-v[0], -v[1], -v[2]])
    } else {
        (w, v)
    };
    let s2 = dot(v, v);
    // psi = 2 atan2(|v|, w) v/|v|, written through s2 to stay smooth at the identity.
    let f = if s2.re() < 1e-8 {
        let w2 = w * w;
        (c::<T>(2.0) / w) * (c::<T>(1.0) - s2 / (w2.scale(3.0)) + s2 * s2 / (w2 * w2).scale(5.0))
    } else {
        let s = s2.sqrt();
        s.atan2(w).scale(2.0) / s
    };
    smul(f, v)
}

/// Left-multiply a rotation by the first-order perturbation `(I + d~)`: the exact derivative of
/// `exp(eps d) R` at eps = 0, used for seeding dual directions.
#[inline]
pub fn perturb_left<T: Real>(d: V3<T>, r: &M3<T>) -> M3<T> {
    madd(r, &mm(&skew(d), r))
}

pub fn to_arr(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}
pub fn quat_to_arr(q: &UnitQuaternion<f64>) -> [[f64; 3]; 3] {
    to_arr(q.to_rotation_matrix().matrix())
}
/// Spatial (left) multiplicative update of a stored quaternion: `q <- exp(theta) q`.
pub fn update_left(q: &UnitQuaternion<f64>, theta: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(Vector3::from(theta)) * q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::structure::real::Dual;

    #[test]
    fn exp_log_round_trip_including_large_angles() {
        for th in [
            [0.0, 0.0, 0.0],
            [1e-5, -2e-5, 3e-6],
            [0.3, -0.2, 1.1],
            [2.9, 0.5, -0.4],
            [0.0, 3.1, 0.0],
        ] {
            let r = exp_map::<f64>(th);
            let rt = mtm(&r, &r);
            for (i, row) in rt.iter().enumerate() {
                for (j, x) in row.iter().enumerate() {
                    assert!((x - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
                }
            }
            let back = log_map(&r);
            for k in 0..3 {
                assert!((back[k] - th[k]).abs() < 1e-12, "{th:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn tangent_right_matches_derivative_of_exp() {
        for p in [[0.3, -0.2, 1.1], [1e-9, 0.0, 2e-9], [2.0, 1.0, -0.5]] {
            for k in 0..3 {
                let pd: V3<Dual<f64>> =
                    std::array::from_fn(|i| Dual::new(p[i], if i == k { 1.0 } else { 0.0 }));
                let r = exp_map(pd);
                let rv: M3<f64> = std::array::from_fn(|i| std::array::from_fn(|j| r[i][j].v));
                let rd: M3<f64> = std::array::from_fn(|i| std::array::from_fn(|j| r[i][j].d));
                let w = mtm(&rv, &rd); // skew(T_R e_k)
                let t = tangent_right::<f64>(p);
                assert!((w[2][1] - t[0][k]).abs() < 1e-12);
                assert!((w[0][2] - t[1][k]).abs() < 1e-12);
                assert!((w[1][0] - t[2][k]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn log_derivative_is_inverse_of_exp_derivative() {
        let p = [0.4, -0.7, 0.2];
        let r = exp_map::<f64>(p);
        // d log(exp(eps e) R) = T_L(p)^{-1} e
        let tl = tangent_left::<f64>(p);
        for k in 0..3 {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            let ed: V3<Dual<f64>> = std::array::from_fn(|i| Dual::new(0.0, e[i]));
            let rp = perturb_left(ed, &m3c(&r));
            let l = log_map(&rp);
            let d = [l[0].d, l[1].d, l[2].d];
            let back = mv(&tl, d);
            for i in 0..3 {
                assert!((back[i] - e[i]).abs() < 1e-12);
            }
        }
    }
}
