//! What the processor offers, for the few kernels that have a twin compiled for AVX (the
//! build targets baseline x86-64; see `docs/architecture.md`, "Vector instructions").

/// True when the processor has AVX: on x86-64, detected at run time (the standard library
/// caches the answer); false on other architectures, whose kernels compile as they are.
pub fn has_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
