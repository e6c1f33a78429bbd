//! What the processor can do, asked at run time, so that one binary (built for baseline
//! x86-64) runs its hottest loops through versions compiled for wider vector instructions
//! where the processor has them (`#[target_feature]` functions, chosen once when a
//! spacecraft or stepper is built).
//!
//! Rust never contracts a multiply and an add into a fused multiply–add by itself, so a loop
//! compiled for AVX2 gives the baseline build's bits: only the width of the registers
//! changes, and every step, event and printed number stays the same. Where the code asks for
//! a fused multiply–add (`f64::mul_add`, `Lane::mul_add`: one rounding of `a·b + c`), the
//! AVX2 versions are compiled with FMA too and execute one instruction; the baseline build
//! calls the C library's `fma`, which rounds the same way (correctly), only more slowly. So
//! the bits are still the same on every processor.

/// Whether this processor has AVX2 and FMA (four f64 per vector instruction instead of two,
/// and a fused multiply–add): every processor with AVX2 that polhode's users are likely to
/// have has both, and the AVX2 versions of the hot loops use both.
pub fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether this processor has AVX-512F (eight f64 per vector instruction).
pub fn avx512_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
