//! Run-time choice of the instruction set for the hand-written kernels (tiled solves, sparse
//! products). The workspace builds for baseline x86-64, so a kernel is written once, generic
//! over [`MulAdd`], and [`dispatch`] runs its body inside a function compiled for AVX-512 or
//! AVX2 + FMA when the CPU has them (the body is `#[inline(always)]`, so it is compiled with
//! the caller's features), otherwise with separate multiply and add.
//!
//! Results differ between the variants only by fused versus separate rounding; on one CPU
//! the choice is fixed, so results stay bit-identical run to run and for any thread count.

/// `a·b + c`, fused where the CPU has FMA.
pub trait MulAdd {
    /// Use the explicit AVX-512 kernels (set only inside `avx512f` code).
    const AVX512: bool = false;
    /// `a·b + c`.
    fn mul_add(a: f64, b: f64, c: f64) -> f64;
}

/// A kernel body generic over the instruction set.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// The body; implementations must be `#[inline(always)]`.
    fn run<F: MulAdd>(self) -> Self::Output;
}

/// Whether this CPU runs the AVX-512 variant.
pub fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Runs `kernel` with the best variant this CPU supports.
pub fn dispatch<K: Kernel>(kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    {
        if has_avx512() {
            // SAFETY: the features were detected on this CPU.
            return unsafe { run_avx512(kernel) };
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: as above.
            return unsafe { run_avx2(kernel) };
        }
    }
    kernel.run::<Separate>()
}

/// The AVX2 + FMA variant on an x86 CPU that has it (`None` elsewhere), for tests that
/// compare every variant.
#[cfg(test)]
pub fn dispatch_avx2<K: Kernel>(kernel: K) -> Option<K::Output> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the features were detected on this CPU.
        return Some(unsafe { run_avx2(kernel) });
    }
    let _ = kernel;
    None
}

/// The portable variant (for tests).
#[cfg(test)]
pub fn run_portable<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<Separate>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
unsafe fn run_avx512<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<Avx512>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<Fused>()
}

/// [`Fused`] plus the explicit AVX-512 kernels.
#[cfg(target_arch = "x86_64")]
struct Avx512;

#[cfg(target_arch = "x86_64")]
impl MulAdd for Avx512 {
    const AVX512: bool = true;
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// Hardware fused multiply–add (only inside `target_feature(enable = "fma")` code).
#[cfg(target_arch = "x86_64")]
struct Fused;

#[cfg(target_arch = "x86_64")]
impl MulAdd for Fused {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a.mul_add(b, c)
    }
}

/// Separate multiply and add (portable fallback; a software fma would be slow).
struct Separate;

impl MulAdd for Separate {
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
}
