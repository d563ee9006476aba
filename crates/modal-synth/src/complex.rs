//! A minimal complex number in f64 (the crate needs only `+`, `×`, `exp`).

use std::ops::{Add, AddAssign, Mul, Sub};

/// Complex number `re + i·im` in f64.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct C64 {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

impl C64 {
    /// Zero.
    pub const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

    /// `re + i·im`.
    pub const fn new(re: f64, im: f64) -> C64 {
        C64 { re, im }
    }

    /// `e^{re} (cos im + i sin im)`.
    pub fn exp(self) -> C64 {
        let m = self.re.exp();
        let (s, c) = self.im.sin_cos();
        C64::new(m * c, m * s)
    }

    /// Modulus `|z|`.
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }

    /// Squared modulus `|z|²`.
    pub fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// Product with a real number.
    pub fn scale(self, k: f64) -> C64 {
        C64::new(self.re * k, self.im * k)
    }

    /// Quotient `self / rhs`.
    pub fn quot(self, rhs: C64) -> C64 {
        let n = rhs.re * rhs.re + rhs.im * rhs.im;
        C64::new((self.re * rhs.re + self.im * rhs.im) / n, (self.im * rhs.re - self.re * rhs.im) / n)
    }

    /// True when both parts are finite.
    pub fn is_finite(self) -> bool {
        self.re.is_finite() && self.im.is_finite()
    }
}

impl Add for C64 {
    type Output = C64;
    fn add(self, r: C64) -> C64 {
        C64::new(self.re + r.re, self.im + r.im)
    }
}

impl AddAssign for C64 {
    fn add_assign(&mut self, r: C64) {
        self.re += r.re;
        self.im += r.im;
    }
}

impl Sub for C64 {
    type Output = C64;
    fn sub(self, r: C64) -> C64 {
        C64::new(self.re - r.re, self.im - r.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    fn mul(self, r: C64) -> C64 {
        C64::new(self.re * r.re - self.im * r.im, self.re * r.im + self.im * r.re)
    }
}
