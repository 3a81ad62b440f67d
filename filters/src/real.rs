//! The scalar type of the filters: `f32` or `f64`, with `libm` for every function beyond `+ − × ÷`.
//!
//! One implementation of each filter serves both precisions through [`Real`]. The trait is small
//! and local rather than `num_traits::Float` because `num-traits` resolves its maths to `std`'s as
//! soon as any crate in a build enables `num-traits/std`; here every square root and
//! trigonometric function is `libm`'s on every target, so a filter computes the same bits on the
//! host and on the Cortex-M (see `CONVENTIONS.md`, *Determinism*).
//!
//! ```
//! use margemu_filters::Real;
//! fn hypot<T: Real>(a: T, b: T) -> T { (a * a + b * b).sqrt() }
//! assert_eq!(hypot(3.0f32, 4.0), 5.0);
//! assert_eq!(hypot(3.0f64, 4.0), 5.0);
//! ```

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A floating-point scalar: `f32` or `f64`.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialOrd
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
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// 0.5.
    const HALF: Self;
    /// π.
    const PI: Self;
    /// The smallest positive normal number.
    const MIN_POSITIVE: Self;

    /// The nearest value of this type (`±inf` beyond its range).
    fn from_f64(v: f64) -> Self;
    /// The exact value in `f64`.
    fn to_f64(self) -> f64;
    /// Square root (`libm`).
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Four-quadrant arctangent of `self / x` (`libm`).
    fn atan2(self, x: Self) -> Self;
    /// Sine (`libm`).
    fn sin(self) -> Self;
    /// Cosine (`libm`).
    fn cos(self) -> Self;
    /// Rounds towards minus infinity (`libm`).
    fn floor(self) -> Self;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> bool;
}

macro_rules! impl_real {
    ($t:ty, $sqrt:path, $fabs:path, $atan2:path, $sin:path, $cos:path, $floor:path) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TWO: Self = 2.0;
            const HALF: Self = 0.5;
            const PI: Self = core::f64::consts::PI as $t;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;

            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $fabs(self)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                $atan2(self, x)
            }
            #[inline(always)]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline(always)]
            fn floor(self) -> Self {
                $floor(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}

impl_real!(
    f32,
    libm::sqrtf,
    libm::fabsf,
    libm::atan2f,
    libm::sinf,
    libm::cosf,
    libm::floorf
);
impl_real!(
    f64,
    libm::sqrt,
    libm::fabs,
    libm::atan2,
    libm::sin,
    libm::cos,
    libm::floor
);
