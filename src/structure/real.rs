//! Scalar abstraction for exact tangents by forward-mode automatic differentiation.
//!
//! Every element residual is written once, generic over [`Real`]; evaluating it with
//! [`Dual`] numbers gives one exact column of the tangent per seeded direction, and nesting
//! (`Dual<Dual<f64>>`) gives second derivatives (used by constraints for `B^T lambda`).
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Scalar used by generic element code: `f64` or a (nested) dual number.
pub trait Real:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Send
    + Sync
    + 'static
{
    fn cst(v: f64) -> Self;
    /// Real part (used for branch decisions only).
    fn re(&self) -> f64;
    fn sqrt(self) -> Self;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn scale(self, s: f64) -> Self {
        self * Self::cst(s)
    }
}

impl Real for f64 {
    #[inline]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline]
    fn re(&self) -> f64 {
        *self
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn sin(self) -> Self {
        f64::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        f64::cos(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        self * s
    }
}

/// First-order dual number `v + d eps` with `eps^2 = 0`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Dual<T> {
    pub v: T,
    pub d: T,
}

impl<T: Real> Dual<T> {
    #[inline]
    pub fn new(v: T, d: T) -> Self {
        Dual { v, d }
    }
    #[inline]
    pub fn var(v: T) -> Self {
        Dual { v, d: T::cst(1.0) }
    }
}

impl<T: Real> Add for Dual<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Dual::new(self.v + o.v, self.d + o.d)
    }
}
impl<T: Real> Sub for Dual<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Dual::new(self.v - o.v, self.d - o.d)
    }
}
impl<T: Real> Mul for Dual<T> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Dual::new(self.v * o.v, self.v * o.d + self.d * o.v)
    }
}
impl<T: Real> Div for Dual<T> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let inv = T::cst(1.0) / o.v;
        let q = self.v * inv;
        Dual::new(q, (self.d - q * o.d) * inv)
    }
}
impl<T: Real> Neg for Dual<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Dual::new(-self.v, -self.d)
    }
}
impl<T: Real> AddAssign for Dual<T> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<T: Real> SubAssign for Dual<T> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<T: Real> MulAssign for Dual<T> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<T: Real> Real for Dual<T> {
    #[inline]
    fn cst(v: f64) -> Self {
        Dual::new(T::cst(v), T::cst(0.0))
    }
    #[inline]
    fn re(&self) -> f64 {
        self.v.re()
    }
    #[inline]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        Dual::new(s, self.d / (s + s))
    }
    #[inline]
    fn sin(self) -> Self {
        Dual::new(self.v.sin(), self.d * self.v.cos())
    }
    #[inline]
    fn cos(self) -> Self {
        Dual::new(self.v.cos(), -(self.d * self.v.sin()))
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
        let den = x.v * x.v + self.v * self.v;
        Dual::new(self.v.atan2(x.v), (x.v * self.d - self.v * x.d) / den)
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        Dual::new(self.v.scale(s), self.d.scale(s))
    }
}

/// Lift an `f64` constant into any scalar.
#[inline]
pub fn c<T: Real>(v: f64) -> T {
    T::cst(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn dual_derivatives_match_calculus() {
        let x = Dual::var(0.7_f64);
        let y = (x.sin() * x.cos() + x.sqrt()) / (x * x + Dual::cst(1.0));
        let f = |x: f64| (x.sin() * x.cos() + x.sqrt()) / (x * x + 1.0);
        let h = 1e-6;
        let fd = (f(0.7 + h) - f(0.7 - h)) / (2.0 * h);
        assert!((y.d - fd).abs() < 1e-8, "{} vs {}", y.d, fd);
        let a = Dual::new(0.3, 1.0).atan2(Dual::new(-0.5, 0.0));
        let fd = ((0.3f64 + h).atan2(-0.5) - (0.3f64 - h).atan2(-0.5)) / (2.0 * h);
        assert!((a.d - fd).abs() < 1e-8);
        // nested duals give mixed second derivatives
        let x = Dual::new(Dual::new(0.4, 1.0), Dual::new(1.0, 0.0));
        let y = x * x * x;
        assert!((y.d.d - 6.0 * 0.4).abs() < 1e-12);
    }
}

/// Multi-lane dual number: one value and `N` directional derivatives, so that all columns of an
/// element tangent come from a single evaluation (shares the real-part work).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualN<const N: usize> {
    pub v: f64,
    pub d: [f64; N],
}

impl<const N: usize> DualN<N> {
    #[inline]
    pub fn new(v: f64, d: [f64; N]) -> Self {
        DualN { v, d }
    }
    #[inline]
    fn chain(self, v: f64, f: f64) -> Self {
        let mut d = self.d;
        for x in d.iter_mut() {
            *x *= f;
        }
        DualN { v, d }
    }
}

impl<const N: usize> Default for DualN<N> {
    fn default() -> Self {
        DualN {
            v: 0.0,
            d: [0.0; N],
        }
    }
}

impl<const N: usize> Add for DualN<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..N {
            self.d[i] += o.d[i];
        }
        self
    }
}
impl<const N: usize> Sub for DualN<N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for i in 0..N {
            self.d[i] -= o.d[i];
        }
        self
    }
}
impl<const N: usize> Mul for DualN<N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut d = [0.0; N];
        for i in 0..N {
            d[i] = self.v * o.d[i] + self.d[i] * o.v;
        }
        DualN { v: self.v * o.v, d }
    }
}
impl<const N: usize> Div for DualN<N> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.v;
        let q = self.v * inv;
        let mut d = [0.0; N];
        for i in 0..N {
            d[i] = (self.d[i] - q * o.d[i]) * inv;
        }
        DualN { v: q, d }
    }
}
impl<const N: usize> Neg for DualN<N> {
    type Output = Self;
    #[inline]
    fn neg(mut self) -> Self {
        self.v = -self.v;
        for x in self.d.iter_mut() {
            *x = -*x;
        }
        self
    }
}
impl<const N: usize> AddAssign for DualN<N> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.v += o.v;
        for i in 0..N {
            self.d[i] += o.d[i];
        }
    }
}
impl<const N: usize> SubAssign for DualN<N> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        self.v -= o.v;
        for i in 0..N {
            self.d[i] -= o.d[i];
        }
    }
}
impl<const N: usize> MulAssign for DualN<N> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<const N: usize> Real for DualN<N> {
    #[inline]
    fn cst(v: f64) -> Self {
        DualN { v, d: [0.0; N] }
    }
    #[inline]
    fn re(&self) -> f64 {
        self.v
    }
    #[inline]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s)
    }
    #[inline]
    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    #[inline]
    fn cos(self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        let den = 1.0 / (x.v * x.v + self.v * self.v);
        let mut d = [0.0; N];
        for i in 0..N {
            d[i] = (x.v * self.d[i] - self.v * x.d[i]) * den;
        }
        DualN {
            v: self.v.atan2(x.v),
            d,
        }
    }
    #[inline]
    fn scale(mut self, s: f64) -> Self {
        self.v *= s;
        for x in self.d.iter_mut() {
            *x *= s;
        }
        self
    }
}
