//! Where kernels run: the [`backend::Backend`] trait (buffers, dispatches,
//! stage times), its two implementations, the GPU through wgpu ([`gpu`]) and
//! the CPU runner that calls the same kernel functions over every
//! invocation id ([`cpu_runner`]), the choice between them ([`device`]),
//! and the table of kernels with their bindings ([`kernels`]); marks on the
//! process's clock ([`timeline`]). Nothing here knows what a BVH or a scene is.
pub mod backend;
pub mod cpu_runner;
pub mod device;
pub mod gpu;
pub mod kernels;
pub(crate) mod kernel_set;
pub mod memory;
pub mod timeline;
