//! # Rendering
//!
//! The path tracer and what it needs:
//! - [`integrator`]: smallpt's estimator and next-event estimation with
//!   multiple importance sampling, iterative, one path at a time per pixel
//!   with path regeneration;
//! - [`caustics`]: light paths for the caustics next-event estimation
//!   cannot find, landing in the pixels the camera sees them in;
//! - [`lights`]: light selection by power and sampling by solid angle or
//!   area (Veach 1997, chapter 9; pbrt-v4's path integrator);
//! - [`sampling`]: directions from uniform numbers, the same bits on both
//!   targets (random numbers: [`crate::gpu::rng`]);
//! - [`sampler`]: the camera paths' low-discrepancy points (Owen-scrambled
//!   Sobol pairs);
//! - [`rays`]: the ray-casting kernels (primary, diffuse, bounce rays, and
//!   rays given by an engine);
//! - [`variants`]: the feature sets render kernels are compiled for.
pub mod caustics;
pub mod integrator;
pub mod lights;
pub mod rays;
pub mod sampler;
pub mod sampling;
pub mod variants;
