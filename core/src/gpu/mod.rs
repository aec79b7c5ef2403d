//! # GPU building blocks
//!
//! The lowest floor, and the one place where the SPIR-V and host builds
//! differ: atomics (`spirv_std` intrinsics on the GPU, `core::sync::atomic`
//! on the host), workgroup memory and barriers written as numbered phases
//! (so the CPU runner can run a workgroup's invocations phase by phase),
//! subgroup operations in the same phases (the GPU's instructions, and an
//! exact emulation for the CPU runner),
//! array access without bounds checks, and counter-based random numbers
//! (the same draws on both targets). Everything above
//! is target-free.
pub mod atomics;
pub mod rng;
pub mod subgroup;
pub mod unchecked;
pub mod workgroup;
