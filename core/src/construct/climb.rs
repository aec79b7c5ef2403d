//! The bottom-up climb with arrival counters: T. Karras, "Maximizing
//! Parallelism in the Construction of BVHs, Octrees, and k-d Trees",
//! HPG 2012, section 4 (the bounding boxes).
//!
//! One invocation per leaf starts at its leaf and climbs towards the root.
//! At each internal node it adds one to that node's counter (even before
//! the dispatch: zeroed, or left so by an earlier climb): the first of the
//! two children's invocations to arrive stops, the second, which then knows
//! both subtrees are done, processes the node and goes on to its parent.
//! Every internal node is thus processed exactly once, by the last of its
//! children, after both of them: a node is finished by exactly one
//! invocation (by induction from the leaves), so its parent's counter is
//! incremented exactly twice, and exactly one of the two increments sees
//! an odd previous value ([`second_arrival`]).
//!
//! Users: the bounds fit ([`crate::construct::fit`]), the treelet rounds'
//! counts, costs and heights ([`crate::construct::treelet::kernels`]) and the
//! wide layout's DP (`crate::layouts::cwbvh::build`) climb with [`Climb`];
//! the `bvh2` layout's refit (`crate::layouts::bvh2::refit_kernel`) with
//! [`second_arrival`], its boxes kept in the layout's nodes;
//! the agglomerative build ([`crate::construct::agglomerate`], after
//! C. Apetrei, "Fast and Simple Agglomerative LBVH Construction", CGVC 2014)
//! uses only the arrival, [`second_arrival_exchange`]: there no parent
//! links exist yet, the climber decides its parent while climbing, and its
//! "counter" is the parent's split slot, through which the first arrival
//! hands the second the far end of its range.
//!
//! Why the second arrival sees both children's writes. Each invocation
//! writes its node's results, then does the read-modify-write on the
//! parent's counter with acquire-release semantics (device scope, on
//! storage buffers; [`atomics::add_device_acq_rel`]). The two RMWs on one
//! counter are ordered (its modification order), and the second reads the
//! value the first wrote, so the first's release synchronizes with the
//! second's acquire: everything that happened before the first arrival (its
//! child's results, and by transitivity everything it acquired lower in its
//! own climb) happens before what the second does after its RMW. The second
//! child's results are its own earlier writes (program order). So the
//! second arrival reads both children complete, writes the parent, and its
//! release at the grandparent passes all of it on, up to the root.
//!
//! On the GPU the results themselves cross invocations, so they are written
//! and read with device-scope (relaxed) atomics too
//! ([`atomics::store_f32`] and friends): under the Vulkan memory model plain
//! accesses are not made available and visible by another invocation's
//! release and acquire. `ORDERED = false` gives the counter relaxed
//! semantics, for the one device that mis-executes the ordered atomic (see
//! [`atomics::add_device_acq_rel`]); the host picks it only there. On the
//! host the CPU runner runs invocations one after another, so nothing races.
use crate::gpu::atomics;

/// One child's arrival at its parent during a bottom-up climb: true for the
/// second of the two children, which then knows both subtrees are done.
/// `ORDERED` releases this subtree's writes and acquires the sibling's
/// (see [`atomics::add_device_acq_rel`] for the device that needs it relaxed).
///
/// The second arrival is the one that finds the counter odd: a climb adds
/// two to every counter it passes, so counters that start even (zeroed)
/// are even again after it, and a tree climbed again and again (a refit
/// every frame) keeps its counters without zeroing them each time.
#[inline]
pub fn second_arrival<const ORDERED: bool>(counter: &mut u32) -> bool {
    let previous = if ORDERED { atomics::add_device_acq_rel(counter, 1) } else { atomics::add_device(counter, 1) };
    previous & 1 != 0
}

/// [`second_arrival`] that also hands over a value: leaves `mine` (below
/// `u32::MAX`) in `slot` (zeroed before the dispatch, it holds value plus
/// one); `None` for the first arrival, `Some` of the first's value for the
/// second. The memory ordering is [`second_arrival`]'s (an exchange is the
/// read-modify-write here).
#[inline]
pub fn second_arrival_exchange<const ORDERED: bool>(slot: &mut u32, mine: u32) -> Option<u32> {
    let previous = if ORDERED {
        atomics::exchange_device_acq_rel(slot, mine + 1)
    } else {
        atomics::exchange_device(slot, mine + 1)
    };
    if previous == 0 { None } else { Some(previous - 1) }
}

/// An invocation's climb from its leaf through a tree with parent links
/// (the root is node 0): each [`Climb::next`] is the next internal node it
/// must process, because it arrived there second.
///
/// ```
/// use treelet_core::construct::climb::Climb;
/// // Root 0 over leaves 1 and 2.
/// let (parents, mut counters) = ([u32::MAX, 0, 0], [0u32]);
/// let mut first = Climb::<true>::new(1);
/// assert_eq!(first.next(&parents, &mut counters), None); // arrived first
/// let mut second = Climb::<true>::new(2);
/// assert_eq!(second.next(&parents, &mut counters), Some(0));
/// assert_eq!(second.child(), 2);
/// assert_eq!(second.next(&parents, &mut counters), None); // the root
/// ```
#[derive(Clone, Copy)]
pub struct Climb<const ORDERED: bool> {
    /// The node this invocation has finished: its start, then the last
    /// node `next` returned; 0 once the climb is over.
    node: u32,
    /// The child the climb came from to `node`.
    child: u32,
}

impl<const ORDERED: bool> Climb<ORDERED> {
    /// A climb from `start` (a leaf whose results are written; node 0 when
    /// the tree is one leaf, and the climb is then over at once).
    #[inline]
    pub fn new(start: u32) -> Self {
        Self { node: start, child: start }
    }

    /// Arrives at the parent of the node finished last (counting on its
    /// counter in `counters`, one per internal node): the parent, which the
    /// caller must now process, if this invocation arrived second; `None`
    /// if it arrived first (the sibling's invocation goes on) or the root
    /// is done, and from then on.
    #[inline]
    pub fn next(&mut self, parents: &[u32], counters: &mut [u32]) -> Option<u32> {
        if self.node == 0 {
            return None;
        }
        let parent = parents[self.node as usize];
        if !second_arrival::<ORDERED>(&mut counters[parent as usize]) {
            self.node = 0;
            return None;
        }
        self.child = self.node;
        self.node = parent;
        Some(parent)
    }

    /// The child of the node `next` returned last that this climb came
    /// from: the one whose results the invocation computed itself.
    #[inline]
    pub fn child(&self) -> u32 {
        self.child
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;
    use std::vec::Vec;

    const INVALID: u32 = u32::MAX;

    /// A tree of `children.len() + 1` leaves in the construct layout
    /// (internal node `i` at `i`, the root 0, leaf `j` at `n - 1 + j`):
    /// the parent links of `children[i] = (left, right)`.
    fn parents_of(children: &[(u32, u32)]) -> Vec<u32> {
        let n = children.len() + 1;
        let mut parents = vec![INVALID; 2 * n - 1];
        for (i, &(l, r)) in children.iter().enumerate() {
            assert_eq!(parents[l as usize], INVALID, "node {l} has two parents");
            assert_eq!(parents[r as usize], INVALID, "node {r} has two parents");
            parents[l as usize] = i as u32;
            parents[r as usize] = i as u32;
        }
        assert!(parents[1..].iter().all(|&p| p != INVALID), "not a tree");
        parents
    }

    /// State of one run: how often each internal node was processed.
    struct Run<'a> {
        children: &'a [(u32, u32)],
        parents: Vec<u32>,
        counters: Vec<u32>,
        processed: Vec<u32>,
    }

    impl<'a> Run<'a> {
        fn new(children: &'a [(u32, u32)]) -> Self {
            let internal = children.len();
            Run { children, parents: parents_of(children), counters: vec![0; internal], processed: vec![0; internal] }
        }

        fn done(&self, node: u32) -> bool {
            node as usize >= self.children.len() || self.processed[node as usize] == 1
        }

        /// One step of `climb`: false when it is over. Checks what
        /// processing the node it returns may rely on.
        fn step(&mut self, climb: &mut Climb<true>) -> bool {
            let Some(p) = climb.next(&self.parents, &mut self.counters) else { return false };
            let (l, r) = self.children[p as usize];
            assert!(climb.child() == l || climb.child() == r, "node {p} reached from {}", climb.child());
            assert!(self.done(l) && self.done(r), "node {p} before its children {l}, {r}");
            self.processed[p as usize] += 1;
            true
        }

        fn check(&self, what: &str) {
            assert!(self.processed.iter().all(|&c| c == 1), "{what}: processed {:?}", self.processed);
            assert!(self.counters.iter().all(|&c| c == 2), "{what}: counters {:?}", self.counters);
        }
    }

    /// Climbs again and again on the same counters, never zeroed between
    /// (as a tree refit every frame keeps them): each climb still processes
    /// every internal node once, after its children.
    #[test]
    fn counters_serve_the_next_climb_without_zeroing() {
        let children: &[(u32, u32)] = &[(6, 1), (2, 3), (7, 8), (4, 5), (9, 10), (11, 12)];
        let n = children.len() as u32 + 1;
        let mut run = Run::new(children);
        for round in 1..=4u32 {
            run.processed.iter_mut().for_each(|p| *p = 0);
            let order: Vec<u32> = if round % 2 == 0 { (0..n).collect() } else { (0..n).rev().collect() };
            let mut climbs: Vec<(Climb<true>, bool)> = order.iter().map(|&j| (Climb::new(n - 1 + j), true)).collect();
            while climbs.iter().any(|c| c.1) {
                for (climb, going) in climbs.iter_mut() {
                    if *going {
                        *going = run.step(climb);
                    }
                }
            }
            assert!(run.processed.iter().all(|&c| c == 1), "round {round}: processed {:?}", run.processed);
            assert!(run.counters.iter().all(|&c| c == 2 * round), "round {round}: counters {:?}", run.counters);
        }
    }

    /// Invocations (leaf indices) one after another, each climbing until it stops.
    fn sequential(children: &[(u32, u32)], order: &[u32]) {
        let n = children.len() as u32 + 1;
        let mut run = Run::new(children);
        for &j in order {
            let mut climb = Climb::<true>::new(n - 1 + j);
            while run.step(&mut climb) {}
            assert!(climb.next(&run.parents, &mut run.counters).is_none(), "a finished climb goes on");
        }
        run.check(&std::format!("order {order:?}"));
    }

    /// All invocations at once, a step each in turn (`order` first), as in lockstep.
    fn interleaved(children: &[(u32, u32)], order: &[u32]) {
        let n = children.len() as u32 + 1;
        let mut run = Run::new(children);
        let mut climbs: Vec<(Climb<true>, bool)> = order.iter().map(|&j| (Climb::new(n - 1 + j), true)).collect();
        while climbs.iter().any(|c| c.1) {
            for (climb, going) in climbs.iter_mut() {
                if *going {
                    *going = run.step(climb);
                }
            }
        }
        run.check(&std::format!("interleaved {order:?}"));
    }

    /// The next permutation in lexicographic order; false after the last.
    fn next_permutation(a: &mut [u32]) -> bool {
        let Some(i) = (1..a.len()).rev().find(|&i| a[i - 1] < a[i]) else { return false };
        let j = (i..a.len()).rev().find(|&j| a[j] > a[i - 1]).unwrap();
        a.swap(i - 1, j);
        a[i..].reverse();
        true
    }

    #[test]
    fn each_internal_node_once_after_its_children() {
        // Internal nodes 0..n-1 (the root 0), leaves from n - 1 on.
        let trees: [&[(u32, u32)]; 5] = [
            &[(1, 2)], // 2 leaves
            &[(1, 4), (2, 3), (5, 6), (7, 8), (9, 10)], // 6 leaves, balanced-ish
            &[(1, 10), (2, 9), (3, 8), (4, 7), (5, 6)], // 6 leaves, a caterpillar
            &[(6, 1), (2, 3), (7, 8), (4, 5), (9, 10), (11, 12)], // 7 leaves, mixed
            &[(1, 2), (3, 4), (5, 6), (7, 8), (9, 10), (11, 12), (13, 14)], // 8 leaves, full
        ];
        for children in trees {
            let n = children.len() as u32 + 1;
            let forwards: Vec<u32> = (0..n).collect();
            let backwards: Vec<u32> = (0..n).rev().collect();
            sequential(children, &forwards);
            sequential(children, &backwards);
            interleaved(children, &forwards);
            interleaved(children, &backwards);
            let mut order = forwards.clone();
            loop {
                sequential(children, &order);
                interleaved(children, &order);
                if !next_permutation(&mut order) {
                    break;
                }
            }
        }
    }

    #[test]
    fn one_leaf_climbs_nowhere() {
        let mut climb = Climb::<true>::new(0);
        assert_eq!(climb.next(&[INVALID], &mut []), None);
    }

    #[test]
    fn exchange_hands_the_first_value_to_the_second() {
        for ordered in [true, false] {
            let mut slot = 0u32;
            let arrive = |slot: &mut u32, v| match ordered {
                true => second_arrival_exchange::<true>(slot, v),
                false => second_arrival_exchange::<false>(slot, v),
            };
            assert_eq!(arrive(&mut slot, 0), None);
            assert_eq!(arrive(&mut slot, 7), Some(0));
            let mut slot = 0u32;
            assert_eq!(arrive(&mut slot, 41), None);
            assert_eq!(arrive(&mut slot, 3), Some(41));
        }
    }
}
