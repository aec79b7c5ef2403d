//! The table of kernels: one entry per compute entry point of the shader
//! crate, with its bindings. The GPU backend builds one pipeline per entry;
//! the CPU runner matches on the same enum to call the same core function.

/// How a kernel uses one storage binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Read,
    ReadWrite,
}
use treelet_core::features::VARIANTS;
use Access::{Read, ReadWrite};

/// Entry points of the render variants, `[linear, BVH]` per entry of
/// `VARIANTS`, named from its names as the shader crate's `render_kernel!`
/// lines are (`render::render_{linear,bvh}_<name>_cs`).
fn render_entry_points() -> &'static [[String; 2]] {
    static NAMES: std::sync::OnceLock<Vec<[String; 2]>> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| {
        VARIANTS.iter().map(|(_, n)| [format!("render::render_linear_{n}_cs"), format!("render::render_bvh_{n}_cs")]).collect()
    })
}

/// Every compute kernel of Treelet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kernel {
    Fill,
    PrimitiveBoxes,
    ReduceBounds,
    Morton,
    SortHistogram,
    ScanReduce,
    ScanSpine,
    ScanDownsweep,
    SortScatter,
    RadixTree,
    Fit,
    /// [`Kernel::Fit`] with a relaxed counter, for CPU adapters.
    FitRelaxed,
    /// Treelet optimization: per-node counts, costs, heights (bottom up).
    TreeletInit,
    /// [`Kernel::TreeletInit`] with relaxed counters, for CPU adapters.
    TreeletInitRelaxed,
    /// Treelet optimization: count treelet roots per height.
    TreeletHistogram,
    /// Treelet optimization: list treelet roots by height.
    TreeletScatter,
    /// Treelet optimization: restructure the treelets of one height, a team of lanes each.
    TreeletRestructure,
    /// SAH leaf collapse and depth-first compaction into fresh arrays.
    Collapse,
    /// Path tracing, closest hit by scanning every primitive, compiled for
    /// the feature set `treelet_core::features::VARIANTS[i]`.
    RenderLinear(u8),
    /// Path tracing, closest hit through the BVH, for `VARIANTS[i]`.
    RenderBvh(u8),
    /// Ray-casting throughput through the BVH (primary or diffuse rays).
    CastBvh,
}

impl Kernel {
    const FIXED: [Kernel; 19] = [
        Kernel::Fill,
        Kernel::PrimitiveBoxes,
        Kernel::ReduceBounds,
        Kernel::Morton,
        Kernel::SortHistogram,
        Kernel::ScanReduce,
        Kernel::ScanSpine,
        Kernel::ScanDownsweep,
        Kernel::SortScatter,
        Kernel::RadixTree,
        Kernel::Fit,
        Kernel::FitRelaxed,
        Kernel::TreeletInit,
        Kernel::TreeletInitRelaxed,
        Kernel::TreeletHistogram,
        Kernel::TreeletScatter,
        Kernel::TreeletRestructure,
        Kernel::Collapse,
        Kernel::CastBvh,
    ];

    /// Every kernel: the fixed ones and each render variant.
    pub fn all() -> Vec<Kernel> {
        let variants = 0..VARIANTS.len() as u8;
        Self::FIXED
            .into_iter()
            .chain(variants.clone().map(Kernel::RenderLinear))
            .chain(variants.map(Kernel::RenderBvh))
            .collect()
    }

    /// Name of the entry point in the shader crate (`<module>::<name>`).
    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::Fill => "fill::fill_cs",
            Kernel::PrimitiveBoxes => "scene::primitive_boxes_cs",
            Kernel::ReduceBounds => "bounds::reduce_bounds_cs",
            Kernel::Morton => "morton::morton_cs",
            Kernel::SortHistogram => "sort::sort_histogram_cs",
            Kernel::ScanReduce => "scan::scan_reduce_cs",
            Kernel::ScanSpine => "scan::scan_spine_cs",
            Kernel::ScanDownsweep => "scan::scan_downsweep_cs",
            Kernel::SortScatter => "sort::sort_scatter_cs",
            Kernel::RadixTree => "radix_tree::radix_tree_cs",
            Kernel::Fit => "fit::fit_cs",
            Kernel::FitRelaxed => "fit::fit_relaxed_cs",
            Kernel::TreeletInit => "treelet::treelet_init_cs",
            Kernel::TreeletInitRelaxed => "treelet::treelet_init_relaxed_cs",
            Kernel::TreeletHistogram => "treelet::treelet_histogram_cs",
            Kernel::TreeletScatter => "treelet::treelet_scatter_cs",
            Kernel::TreeletRestructure => "treelet::treelet_restructure_cs",
            Kernel::Collapse => "treelet::collapse_cs",
            Kernel::RenderLinear(i) => &render_entry_points()[i as usize][0],
            Kernel::RenderBvh(i) => &render_entry_points()[i as usize][1],
            Kernel::CastBvh => "render::cast_bvh_cs",
        }
    }

    /// Bindings in order; binding 0 is always the parameter struct.
    pub fn bindings(self) -> &'static [Access] {
        match self {
            Kernel::Fill => &[Read, ReadWrite],
            Kernel::PrimitiveBoxes => &[Read, Read, Read, ReadWrite],
            Kernel::ReduceBounds => &[Read, Read, ReadWrite],
            Kernel::Morton => &[Read, Read, ReadWrite, ReadWrite],
            Kernel::SortHistogram => &[Read, Read, ReadWrite],
            Kernel::ScanReduce => &[Read, Read, ReadWrite],
            Kernel::ScanSpine => &[Read, ReadWrite],
            Kernel::ScanDownsweep => &[Read, ReadWrite, Read],
            Kernel::SortScatter => &[Read, Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::RadixTree => &[Read, Read, ReadWrite, ReadWrite],
            Kernel::Fit | Kernel::FitRelaxed => &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::TreeletInit | Kernel::TreeletInitRelaxed => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::TreeletHistogram => &[Read, Read, Read, ReadWrite],
            Kernel::TreeletScatter => &[Read, Read, Read, ReadWrite, ReadWrite],
            Kernel::TreeletRestructure => {
                &[Read, Read, Read, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite, ReadWrite]
            }
            Kernel::Collapse => &[Read, Read, Read, Read, Read, Read, ReadWrite, ReadWrite, ReadWrite],
            Kernel::RenderLinear(_) | Kernel::RenderBvh(_) | Kernel::CastBvh => {
                &[Read, Read, Read, Read, Read, ReadWrite, Read]
            }
        }
    }
}
