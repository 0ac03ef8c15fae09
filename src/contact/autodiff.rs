//! Forward-mode dual numbers for the exact contact tangent.
//!
//! A `Dual<N>` carries a value and its gradient with respect to `N` seed
//! variables (the nodal coordinates of one contact link, at most 24). Every
//! operation applies the chain rule to the gradient, so a kernel written once
//! in terms of [`Scalar`] yields the residual with `f64` and the residual plus
//! its exact Jacobian with `Dual<N>`. Everything is `Copy` and lives in fixed
//! arrays: no operation allocates.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Value `re` and partial derivatives `eps[i] = ∂re/∂u_i`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<const N: usize> {
    pub re: f64,
    pub eps: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// A value that does not depend on any variable.
    #[inline]
    pub const fn constant(v: f64) -> Self {
        Dual {
            re: v,
            eps: [0.0; N],
        }
    }

    /// The `i`-th independent variable with value `v` (unit gradient).
    /// An index `i >= N` yields a constant: there is no such variable.
    #[inline]
    pub fn variable(v: f64, i: usize) -> Self {
        let mut d = Self::constant(v);
        if let Some(e) = d.eps.get_mut(i) {
            *e = 1.0;
        }
        d
    }

    /// `√x`, derivative `1/(2√x)`. At `x = 0` the derivative is infinite; the
    /// contact kernels never take the root of a vanishing norm (they reject
    /// degenerate geometry first), so no special case is made here.
    #[inline]
    pub fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s)
    }

    /// `1/x`, derivative `−1/x²`.
    #[inline]
    pub fn recip(self) -> Self {
        let r = 1.0 / self.re;
        self.chain(r, -r * r)
    }

    /// `f(self)` given `f = value` and `f' = slope` at `self.re`.
    #[inline]
    fn chain(mut self, value: f64, slope: f64) -> Self {
        // In place: `array::map` built a second array (an eighth of the
        // dual-number instructions of a frictional mortar run).
        self.re = value;
        for e in &mut self.eps {
            *e *= slope;
        }
        self
    }
}

impl<const N: usize> Default for Dual<N> {
    #[inline]
    fn default() -> Self {
        Self::constant(0.0)
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, rhs: Self) -> Self {
        self += rhs;
        self
    }
}

impl<const N: usize> AddAssign for Dual<N> {
    #[inline]
    fn add_assign(&mut self, rhs: Self) {
        self.re += rhs.re;
        for i in 0..N {
            self.eps[i] += rhs.eps[i];
        }
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, rhs: Self) -> Self {
        self -= rhs;
        self
    }
}

impl<const N: usize> SubAssign for Dual<N> {
    #[inline]
    fn sub_assign(&mut self, rhs: Self) {
        self.re -= rhs.re;
        for i in 0..N {
            self.eps[i] -= rhs.eps[i];
        }
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    #[inline]
    fn mul(self, rhs: Self) -> Self {
        let mut out = Self::constant(self.re * rhs.re);
        for i in 0..N {
            out.eps[i] = self.eps[i] * rhs.re + self.re * rhs.eps[i];
        }
        out
    }
}

impl<const N: usize> MulAssign for Dual<N> {
    #[inline]
    fn mul_assign(&mut self, rhs: Self) {
        *self = *self * rhs;
    }
}

impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    /// Quotient rule `(a/b)' = (a' − (a/b) b') / b`, with `1/b` formed once.
    #[inline]
    fn div(self, rhs: Self) -> Self {
        let inv = 1.0 / rhs.re;
        let q = self.re * inv;
        let mut out = Self::constant(q);
        for i in 0..N {
            out.eps[i] = (self.eps[i] - q * rhs.eps[i]) * inv;
        }
        out
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.chain(-self.re, -1.0)
    }
}

impl<const N: usize> Add<f64> for Dual<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, rhs: f64) -> Self {
        self.re += rhs;
        self
    }
}

impl<const N: usize> Sub<f64> for Dual<N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, rhs: f64) -> Self {
        self.re -= rhs;
        self
    }
}

impl<const N: usize> Mul<f64> for Dual<N> {
    type Output = Self;
    #[inline]
    fn mul(self, rhs: f64) -> Self {
        self.chain(self.re * rhs, rhs)
    }
}

impl<const N: usize> Div<f64> for Dual<N> {
    type Output = Self;
    #[inline]
    fn div(self, rhs: f64) -> Self {
        self * (1.0 / rhs)
    }
}

impl<const N: usize> Add<Dual<N>> for f64 {
    type Output = Dual<N>;
    #[inline]
    fn add(self, rhs: Dual<N>) -> Dual<N> {
        rhs + self
    }
}

impl<const N: usize> Sub<Dual<N>> for f64 {
    type Output = Dual<N>;
    #[inline]
    fn sub(self, rhs: Dual<N>) -> Dual<N> {
        -rhs + self
    }
}

impl<const N: usize> Mul<Dual<N>> for f64 {
    type Output = Dual<N>;
    #[inline]
    fn mul(self, rhs: Dual<N>) -> Dual<N> {
        rhs * self
    }
}

impl<const N: usize> Div<Dual<N>> for f64 {
    type Output = Dual<N>;
    #[inline]
    fn div(self, rhs: Dual<N>) -> Dual<N> {
        // s/b: derivative −s b'/b².
        let inv = 1.0 / rhs.re;
        rhs.chain(self * inv, -self * inv * inv)
    }
}

/// The arithmetic the contact kernels need, implemented by `f64` (residual
/// only) and `Dual<N>` (residual and Jacobian), so the kinematics are written
/// once and the tangent cannot drift from the residual.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    fn from_f64(v: f64) -> Self;
    /// The value without derivatives (decisions such as open/closed and
    /// degeneracy checks are made on it).
    fn re(&self) -> f64;
    fn sqrt(self) -> Self;
    fn recip(self) -> Self;
    /// `f(at)` given `f`'s value and gradient at `at`'s values: `value`
    /// with the derivative `grad · ∂at`. What a function of two
    /// parametric coordinates costs in `Dual<N>` is then one pass over the
    /// gradient, however many operations `f` takes in f64.
    fn linearised(value: f64, grad: [f64; 2], at: &[Self; 2]) -> Self;
    /// Zero with a zero gradient: a coefficient that adds nothing.
    fn is_zero(&self) -> bool;
    /// `self += a b` in place (the accumulation of the segment integrals:
    /// no temporaries of the product).
    #[inline]
    fn add_product(&mut self, a: Self, b: Self) {
        *self = *self + a * b;
    }
    /// `self += a s` in place (sums of nodal values times shape values).
    #[inline]
    fn add_scaled(&mut self, a: &Self, s: f64) {
        *self = *self + *a * s;
    }
}

impl Scalar for f64 {
    #[inline]
    fn from_f64(v: f64) -> Self {
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
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline]
    fn linearised(value: f64, _: [f64; 2], _: &[f64; 2]) -> Self {
        value
    }
    #[inline]
    fn is_zero(&self) -> bool {
        *self == 0.0
    }
}

impl<const N: usize> Scalar for Dual<N> {
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self::constant(v)
    }
    #[inline]
    fn re(&self) -> f64 {
        self.re
    }
    #[inline]
    fn sqrt(self) -> Self {
        Dual::sqrt(self)
    }
    #[inline]
    fn recip(self) -> Self {
        Dual::recip(self)
    }
    #[inline]
    fn linearised(value: f64, grad: [f64; 2], at: &[Self; 2]) -> Self {
        let mut out = Self::constant(value);
        for i in 0..N {
            out.eps[i] = grad[0] * at[0].eps[i] + grad[1] * at[1].eps[i];
        }
        out
    }
    #[inline]
    fn is_zero(&self) -> bool {
        self.re == 0.0 && self.eps.iter().all(|e| *e == 0.0)
    }
    #[inline]
    fn add_scaled(&mut self, a: &Self, s: f64) {
        self.re += a.re * s;
        for i in 0..N {
            self.eps[i] += a.eps[i] * s;
        }
    }
    #[inline]
    fn add_product(&mut self, a: Self, b: Self) {
        self.re += a.re * b.re;
        for i in 0..N {
            self.eps[i] += a.eps[i] * b.re + a.re * b.eps[i];
        }
    }
}

/// A 3-vector of scalars (`[Dual<N>; 3]` or `[f64; 3]`).
pub type Vec3<T> = [T; 3];

#[inline]
pub fn constant3<T: Scalar>(v: [f64; 3]) -> Vec3<T> {
    [T::from_f64(v[0]), T::from_f64(v[1]), T::from_f64(v[2])]
}

#[inline]
pub fn re3<T: Scalar>(v: &Vec3<T>) -> [f64; 3] {
    [v[0].re(), v[1].re(), v[2].re()]
}

#[inline]
pub fn add<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub fn sub<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub fn scale<T: Scalar>(a: &Vec3<T>, s: T) -> Vec3<T> {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub fn scale_f64<T: Scalar>(a: &Vec3<T>, s: f64) -> Vec3<T> {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a + s·b`, the update that builds interpolated positions and tangents.
#[inline]
pub fn axpy<T: Scalar>(a: &Vec3<T>, s: f64, b: &Vec3<T>) -> Vec3<T> {
    [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s]
}

#[inline]
pub fn dot<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub fn cross<T: Scalar>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub fn norm<T: Scalar>(a: &Vec3<T>) -> T {
    dot(a, a).sqrt()
}

/// A scalar that can be seeded as the `i`-th independent variable (f64
/// ignores the index: values only). The mortar kernels seed a segment's
/// node coordinates with it.
pub trait Seed: Scalar {
    fn seed(v: f64, i: usize) -> Self;
    /// Value `v` with derivative `slope` along variable `i` (an affine
    /// function of that variable, such as a slip increment).
    fn seed_scaled(v: f64, i: usize, slope: f64) -> Self;
    /// Adds `v` to the derivative along variable `i` (f64: nothing).
    fn add_derivative(&mut self, i: usize, v: f64);
}

impl Seed for f64 {
    fn seed(v: f64, _: usize) -> Self {
        v
    }

    fn seed_scaled(v: f64, _: usize, _: f64) -> Self {
        v
    }

    fn add_derivative(&mut self, _: usize, _: f64) {}
}

// One impl for every size: the segment variables (`D`) and a rigid
// master's slave-facet variables alike.
impl<const N: usize> Seed for Dual<N> {
    fn seed(v: f64, i: usize) -> Self {
        Dual::variable(v, i)
    }

    fn seed_scaled(v: f64, i: usize, slope: f64) -> Self {
        let mut d = Dual::constant(v);
        if let Some(e) = d.eps.get_mut(i) {
            *e = slope;
        }
        d
    }

    fn add_derivative(&mut self, i: usize, v: f64) {
        if let Some(e) = self.eps.get_mut(i) {
            *e += v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type D3 = Dual<3>;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-14 * (1.0 + b.abs())
    }

    fn assert_grad(d: D3, re: f64, grad: [f64; 3]) {
        assert!(close(d.re, re), "value {} vs {}", d.re, re);
        for (i, (g, e)) in d.eps.iter().zip(grad).enumerate() {
            assert!(close(*g, e), "d/du{i}: {g} vs {e}");
        }
    }

    /// Three variables x, y, z at fixed values, used by every test below.
    fn xyz() -> (D3, D3, D3, [f64; 3]) {
        let v = [1.3, -0.7, 2.1];
        (
            D3::variable(v[0], 0),
            D3::variable(v[1], 1),
            D3::variable(v[2], 2),
            v,
        )
    }

    #[test]
    fn constructors() {
        let c = D3::constant(4.0);
        assert_eq!(c.eps, [0.0; 3]);
        let v = D3::variable(2.0, 1);
        assert_eq!(v.eps, [0.0, 1.0, 0.0]);
        // Out-of-range index must not panic: it is simply a constant.
        assert_eq!(D3::variable(2.0, 7).eps, [0.0; 3]);
        assert_eq!(D3::default(), D3::constant(0.0));
    }

    #[test]
    fn arithmetic_matches_hand_derivatives() {
        let (x, y, z, [a, b, c]) = xyz();
        assert_grad(x + y, a + b, [1.0, 1.0, 0.0]);
        assert_grad(x - z, a - c, [1.0, 0.0, -1.0]);
        assert_grad(x * y, a * b, [b, a, 0.0]);
        assert_grad(x / z, a / c, [1.0 / c, 0.0, -a / (c * c)]);
        assert_grad(-y, -b, [0.0, -1.0, 0.0]);
        // f = x² y / z + 3
        let f = x * x * y / z + 3.0;
        assert_grad(
            f,
            a * a * b / c + 3.0,
            [2.0 * a * b / c, a * a / c, -a * a * b / (c * c)],
        );
    }

    #[test]
    fn mixed_f64_operands() {
        let (x, _, z, [a, _, c]) = xyz();
        assert_grad(x + 2.0, a + 2.0, [1.0, 0.0, 0.0]);
        assert_grad(2.0 + x, a + 2.0, [1.0, 0.0, 0.0]);
        assert_grad(x - 2.0, a - 2.0, [1.0, 0.0, 0.0]);
        assert_grad(2.0 - x, 2.0 - a, [-1.0, 0.0, 0.0]);
        assert_grad(x * 3.0, 3.0 * a, [3.0, 0.0, 0.0]);
        assert_grad(3.0 * z, 3.0 * c, [0.0, 0.0, 3.0]);
        assert_grad(z / 4.0, c / 4.0, [0.0, 0.0, 0.25]);
        assert_grad(4.0 / z, 4.0 / c, [0.0, 0.0, -4.0 / (c * c)]);
        let mut m = x;
        m += z;
        m -= x;
        m *= z;
        assert_grad(m, c * c, [0.0, 0.0, 2.0 * c]);
    }

    #[test]
    fn sqrt_and_recip() {
        let (x, y, z, [a, b, c]) = xyz();
        // √(x² + y² + z²): gradient (x, y, z)/r.
        let r = (x * x + y * y + z * z).sqrt();
        let rv = (a * a + b * b + c * c).sqrt();
        assert_grad(r, rv, [a / rv, b / rv, c / rv]);
        assert_grad(x.recip(), 1.0 / a, [-1.0 / (a * a), 0.0, 0.0]);
    }

    #[test]
    fn vector_helpers() {
        let (x, y, z, [a, b, c]) = xyz();
        let u = [x, y, z];
        let v = constant3::<D3>([0.5, -2.0, 1.5]);
        // d/du (u·v) = v
        assert_grad(dot(&u, &v), 0.5 * a - 2.0 * b + 1.5 * c, [0.5, -2.0, 1.5]);
        // (u × v)_0 = y v2 − z v1
        let w = cross(&u, &v);
        assert_grad(w[0], 1.5 * b + 2.0 * c, [0.0, 1.5, 2.0]);
        assert_grad(w[2], -2.0 * a - 0.5 * b, [-2.0, -0.5, 0.0]);
        let n = norm(&u);
        let nv = (a * a + b * b + c * c).sqrt();
        assert_grad(n, nv, [a / nv, b / nv, c / nv]);
        let s = scale(&sub(&u, &v), x);
        // s_1 = (y + 2) x
        assert_grad(s[1], (b + 2.0) * a, [b + 2.0, a, 0.0]);
        let t = axpy(&add(&u, &v), 2.0, &u);
        assert_grad(t[2], 3.0 * c + 1.5, [0.0, 0.0, 3.0]);
        assert_grad(scale_f64(&u, -1.0)[0], -a, [-1.0, 0.0, 0.0]);
        assert_eq!(re3(&u), [a, b, c]);
    }

    #[test]
    fn f64_scalar_agrees_with_dual_value() {
        fn f<T: Scalar>(x: T, y: T) -> T {
            (x * x + y).sqrt().recip() * 2.0 - x / y
        }
        let d = f(D3::variable(1.5, 0), D3::variable(0.8, 1));
        let p = f(1.5, 0.8);
        assert!(close(d.re, p));
        // Central differences confirm the gradient of a composite.
        let h = 1e-6;
        let gx = (f(1.5 + h, 0.8) - f(1.5 - h, 0.8)) / (2.0 * h);
        let gy = (f(1.5, 0.8 + h) - f(1.5, 0.8 - h)) / (2.0 * h);
        assert!((d.eps[0] - gx).abs() < 1e-8 && (d.eps[1] - gy).abs() < 1e-8);
    }

    #[test]
    fn twenty_four_variables() {
        let mut s = Dual::<24>::constant(0.0);
        for i in 0..24 {
            let v = Dual::<24>::variable(i as f64, i);
            s += v * v;
        }
        for (i, e) in s.eps.iter().enumerate() {
            assert_eq!(*e, 2.0 * i as f64);
        }
    }
}
