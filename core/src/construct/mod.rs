//! # Construction
//!
//! Building the binary tree, stage by stage:
//!
//! | stage | module | paper |
//! |---|---|---|
//! | primitive boxes | [`primitive_boxes`] | |
//! | large triangles split into pieces (optional) | [`presplit`] | Karras & Aila 2013, section 5.1 |
//! | centroid bounds | [`bounds`] | parallel reduction |
//! | Morton codes | [`morton`] | Karras 2012, section 4 |
//! | sort | [`sort`] (the Onesweep pass), [`sort::scan`]; [`sort::multisplit`] (the pass ranked by subgroups), [`sort::multisplit_rank`] (its ranking alone), [`sort::ties`] (high digits first, then ties); [`sort::passes`] (their kernels, listed once) | Adinets & Merrill 2022 (Onesweep) |
//! | radix tree | [`radix_tree`] | Karras 2012, section 3, figure 4 |
//! | bottom-up climb (fit, agglomerate, treelet counts, wide DP) | [`climb`]; [`climb_queue`] (climbs handed from one kernel to the next) | Karras 2012, section 4; Apetrei 2014 |
//! | bottom-up boxes | [`fit`] | Karras 2012, section 4 |
//! | hierarchy and boxes in one pass | [`agglomerate`]; [`agglomerate_subgroup`] (its lowest levels merged within subgroups) | Apetrei 2014 |
//! | treelet restructuring | [`treelet`] (the DP), [`treelet::kernels`] (the device schedule) | Karras & Aila 2013, section 4 |
//! | reinsertion of nodes where they lower the SAH most | [`reinsert`] | Meister & Bittner 2018 |
//! | SAH leaf collapse, depth-first compaction | [`collapse`] | Karras & Aila 2013, section 4.4 |
//! | SAH cost | [`sah`] | MacDonald & Booth 1990 |
//! | an instanced scene's top level: instance records and world boxes | [`instances`] | |
//! | buffer fills (the fit's arrival counters) | [`fill`] | |
//!
//! Node layout: `n` leaves and `n - 1` internal nodes in one array of
//! `2n - 1` [`Node`](crate::geometry::buffers::Node)s. Internal node `i`
//! sits at index `i` (the root is 0), leaf `j` (the `j`-th primitive in
//! Morton order) at index `n - 1 + j`.
pub mod agglomerate;
pub mod agglomerate_subgroup;
pub mod bounds;
pub mod climb;
pub mod climb_queue;
pub mod collapse;
pub mod fill;
pub mod fit;
pub mod hploc;
pub mod instances;
pub mod morton;
pub mod presplit;
pub mod primitive_boxes;
pub mod radix_tree;
pub mod reinsert;
pub mod sah;
pub mod sort;
pub mod treelet;
