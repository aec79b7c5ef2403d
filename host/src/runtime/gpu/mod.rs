//! The wgpu runtime: the kernels' SPIR-V ([`shaders`]), device set-up ([`context`]) and the [`Backend`]
//! implementation that records, times and submits dispatches ([`backend`]).
//!
//! [`Backend`]: crate::runtime::backend::Backend
pub mod backend;
pub mod context;
pub mod shaders;

pub use backend::GpuBackend;
pub use context::{quiet_mesa_runtime_dir, GpuContext};
pub use shaders::{COMMITTED_SHADERS_PATH, SHADER_BUILD_PEAK_RSS_KB, SHADERS, SHADERS_REBUILT};
