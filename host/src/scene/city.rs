//! `city:N[:SEED]`: a generated city of about N triangles whose sizes span
//! as many orders of magnitude as an architectural model's, for BVH
//! benchmarks.
//!
//! Scanned meshes and `terrain:N` have triangles of one size; real scenes
//! (public architectural models such as San Miguel or Bistro) mix a ground
//! of a few huge triangles, long walls, needle-thin cables and railings, and
//! clouds of tiny leaves, over six orders of magnitude of area and more.
//! That is what splits and Morton codes find hard (a huge triangle straddles
//! every split, a leaf cloud packs thousands of boxes into one cell), and
//! those models are too large to ship with the tests: this stands in.
//!
//! The city covers 200 x 200 units (y up): one ground of 2 triangles, 4 x 4
//! blocks raised as sidewalk slabs between 12-unit streets, two of them
//! parks. The other blocks hold buildings (boxes of 2-triangle wall and roof
//! quads, 5 to 30 units tall, one in eight a tower up to 120) and three open
//! rooms (floor, walls with a door, a ceiling with a hole, a table), so that
//! a camera can sit inside. That layout (500 to 1000 triangles whatever N)
//! depends on the seed alone; what is left of N is shared out
//! ([`WINDOWS`] .. [`MARKINGS`]) as detail whose density grows with N:
//! windows on the walls, power lines and railings (ribbons of aspect
//! 1000 and more), cars, benches, bollards and rooftop units, road
//! markings, trees (a trunk and hundreds of tiny leaves each), and grass in
//! the parks, which takes the rest so that the count is N exactly (or the
//! layout's, for N below it).
//!
//! Deterministic for (N, seed) on every platform: PCG streams, one per kind
//! of detail, and nothing but IEEE-exact arithmetic (sums, products,
//! square roots; no transcendental functions, whose results vary by libm).
use glam::{Vec2, Vec3};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use treelet_core::geometry::triangle::Triangle;

/// Half the side of the city's square.
const HALF: f32 = 100.0;
/// Blocks per side, and their pitch (a block and a street).
const BLOCKS: usize = 4;
const PITCH: f32 = 50.0;
/// Half a street's width.
const STREET: f32 = 6.0;
/// Height of the sidewalk slabs: buildings, trees and grass stand on them.
const KERB: f32 = 0.15;
/// Blocks that are parks, and building lots that are open rooms.
const PARKS: usize = 2;
const ROOMS: usize = 3;

/// Shares of the triangles the layout leaves; grass takes the rest (at
/// least 20%, and whatever a kind could not place).
pub const WINDOWS: f64 = 0.24;
pub const FOLIAGE: f64 = 0.30;
pub const DETAIL: f64 = 0.16;
pub const THIN: f64 = 0.08;
pub const MARKINGS: f64 = 0.02;

/// About `n` triangles of a city (see the module docs): exactly `n` from
/// about 1000 on, deterministic for `(n, seed)`.
pub fn city(n: usize, seed: u64) -> Vec<Triangle> {
    build(n, seed).tris
}

/// The city, with where each kind of triangle ends ([`Mesh::parts`]).
fn build(n: usize, seed: u64) -> Mesh {
    // One stream per kind: the layout is the same at every n.
    let stream = |k: u64| Pcg64::seed_from_u64(seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let layout = Layout::new(&mut stream(0));
    let mut m = Mesh { tris: Vec::with_capacity(n.max(1024)), parts: Vec::new() };
    m.quad(Vec3::new(-HALF, 0.0, -HALF), Vec3::Z * 2.0 * HALF, Vec3::X * 2.0 * HALF);
    m.part("ground");
    for &(lo, hi) in &layout.blocks {
        m.cuboid(Vec3::new(lo.x, 0.0, lo.y), Vec3::new(hi.x, KERB, hi.y), false);
    }
    m.part("sidewalks");
    for &(lo, hi) in &layout.buildings {
        m.cuboid(lo, hi, false);
    }
    m.part("buildings");
    for &(lo, hi) in &layout.rooms {
        room(&mut m, lo, hi);
    }
    m.part("rooms");
    let rest = n.saturating_sub(m.len()) as f64;
    let share = |f: f64| (rest * f) as usize;
    windows(&mut m, &layout, share(WINDOWS));
    m.part("windows");
    thin(&mut m, &layout, share(THIN), &mut stream(1));
    m.part("power lines, railings");
    details(&mut m, &layout, share(DETAIL), &mut stream(2));
    m.part("cars, benches, bollards, rooftop units");
    markings(&mut m, share(MARKINGS), &mut stream(3));
    m.part("road markings");
    trees(&mut m, &layout, share(FOLIAGE), &mut stream(4));
    m.part("trees");
    let blades = n.saturating_sub(m.len());
    grass(&mut m, &layout, blades, &mut stream(5));
    m.part("grass");
    m
}

/// Triangles, and the kinds they come in.
struct Mesh {
    tris: Vec<Triangle>,
    /// Each kind's name and the end of its triangles, in order.
    parts: Vec<(&'static str, usize)>,
}

impl Mesh {
    fn len(&self) -> usize {
        self.tris.len()
    }

    /// Ends the current kind of triangles.
    fn part(&mut self, name: &'static str) {
        self.parts.push((name, self.len()));
    }

    fn tri(&mut self, a: Vec3, b: Vec3, c: Vec3) {
        self.tris.push(Triangle::new(a.to_array(), b.to_array(), c.to_array()));
    }

    /// The parallelogram at corner `o` with edges `u` and `v` (facing
    /// `u × v`): 2 triangles.
    fn quad(&mut self, o: Vec3, u: Vec3, v: Vec3) {
        let (b, c, d) = (o + u, o + u + v, o + v);
        self.tri(o, b, c);
        self.tri(o, c, d);
    }

    /// An axis-aligned box, faces outward: sides and top (10 triangles),
    /// and the bottom when `bottom` (12).
    fn cuboid(&mut self, lo: Vec3, hi: Vec3, bottom: bool) {
        let d = hi - lo;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        self.quad(lo, y, x);
        self.quad(lo, z, y);
        self.quad(hi, -x, -y);
        self.quad(hi, -y, -z);
        self.quad(hi, -z, -x);
        if bottom {
            self.quad(lo, x, z);
        }
    }

    /// A hexagonal prism of radius `r` along `base .. base + axis`: 12 side
    /// triangles, and 8 for its two ends when `caps` (a hexagon needs no
    /// sines: its corners are at ±1, ±1/2 and ±√3/2).
    fn prism(&mut self, base: Vec3, axis: Vec3, r: f32, caps: bool) {
        let helper = if axis.y.abs() < 0.9 * axis.length() { Vec3::Y } else { Vec3::X };
        let u = axis.cross(helper).normalize() * r;
        let v = axis.normalize().cross(u);
        const S: f32 = 0.866_025_4;
        let ring =
            [(1.0, 0.0), (0.5, S), (-0.5, S), (-1.0, 0.0), (-0.5, -S), (0.5, -S)].map(|(c, s)| base + u * c + v * s);
        for k in 0..6 {
            let (a, b) = (ring[k], ring[(k + 1) % 6]);
            self.quad(a, b - a, axis);
        }
        if caps {
            let top = ring.map(|p| p + axis);
            for k in 1..5 {
                self.tri(ring[0], ring[k + 1], ring[k]);
                self.tri(top[0], top[k], top[k + 1]);
            }
        }
    }
}

/// What the seed alone decides: blocks, parks, buildings, rooms.
struct Layout {
    /// Each block's corners (x, z), its sidewalk slab included.
    blocks: Vec<(Vec2, Vec2)>,
    /// Indices of the park blocks.
    parks: Vec<usize>,
    /// Boxes, from the slab's top up (open rooms are apart).
    buildings: Vec<(Vec3, Vec3)>,
    rooms: Vec<(Vec3, Vec3)>,
}

impl Layout {
    fn new(rng: &mut Pcg64) -> Layout {
        let side = PITCH - 2.0 * STREET;
        let blocks: Vec<(Vec2, Vec2)> = (0..BLOCKS * BLOCKS)
            .map(|b| {
                let lo = Vec2::new((b % BLOCKS) as f32, (b / BLOCKS) as f32) * PITCH - HALF + STREET;
                (lo, lo + side)
            })
            .collect();
        let mut order: Vec<usize> = (0..blocks.len()).collect();
        order.shuffle(rng);
        let (mut buildings, mut rooms) = (Vec::new(), Vec::new());
        for (k, &b) in order[PARKS..].iter().enumerate() {
            // Lots in a grid inside a 3-unit sidewalk, a building in each with
            // a margin of its own (so neighbours never touch).
            let (lo, hi) = (blocks[b].0 + 3.0, blocks[b].1 - 3.0);
            let (nx, nz) = (rng.random_range(1..=3), rng.random_range(1..=2));
            let cell = (hi - lo) / Vec2::new(nx as f32, nz as f32);
            for i in 0..nx {
                for j in 0..nz {
                    let corner = lo + cell * Vec2::new(i as f32, j as f32);
                    let mut margin = || Vec2::new(rng.random_range(0.5..2.0), rng.random_range(0.5..2.0));
                    let (a, c) = (corner + margin(), corner + cell - margin());
                    if k < ROOMS && i == 0 && j == 0 {
                        rooms.push((Vec3::new(a.x, KERB, a.y), Vec3::new(c.x, KERB + 4.0, c.y)));
                        continue;
                    }
                    // Mostly low, skewed further low; one in eight a tower.
                    let height = if rng.random_bool(0.125) {
                        rng.random_range(45.0..120.0)
                    } else {
                        let u: f32 = rng.random();
                        5.0 + 25.0 * u * u
                    };
                    buildings.push((Vec3::new(a.x, KERB, a.y), Vec3::new(c.x, KERB + height, c.y)));
                }
            }
        }
        Layout { blocks, parks: order[..PARKS].to_vec(), buildings, rooms }
    }

    /// A random point of a park, `margin` in from its edges.
    fn park_spot(&self, rng: &mut Pcg64, margin: f32) -> Vec2 {
        let (lo, hi) = self.blocks[self.parks[rng.random_range(0..self.parks.len())]];
        Vec2::new(rng.random_range(lo.x + margin..hi.x - margin), rng.random_range(lo.y + margin..hi.y - margin))
    }

    /// A random point of a sidewalk, `inset` in from the kerb.
    fn sidewalk_spot(&self, rng: &mut Pcg64, inset: f32) -> Vec2 {
        let (lo, hi) = self.blocks[rng.random_range(0..self.blocks.len())];
        let t = rng.random_range(0.0..1.0);
        let (x, z) = (lo.x + 1.0 + t * (hi.x - lo.x - 2.0), lo.y + 1.0 + t * (hi.y - lo.y - 2.0));
        match rng.random_range(0..4) {
            0 => Vec2::new(x, lo.y + inset),
            1 => Vec2::new(x, hi.y - inset),
            2 => Vec2::new(lo.x + inset, z),
            _ => Vec2::new(hi.x - inset, z),
        }
    }
}

/// The streets between blocks, as (axis, centre): axis 0 runs along x at
/// z = centre, axis 1 along z at x = centre.
fn inner_streets() -> impl Iterator<Item = (usize, f32)> {
    (0..2).flat_map(|axis| (1..BLOCKS).map(move |k| (axis, k as f32 * PITCH - HALF)))
}

/// Where a street runs beside blocks (not through crossings): (start, end)
/// along it.
fn segments() -> impl Iterator<Item = (f32, f32)> {
    (0..BLOCKS).map(|i| (i as f32 * PITCH - HALF + STREET, (i + 1) as f32 * PITCH - HALF - STREET))
}

/// The point `along` and `across` a street (axis, centre) at height `y`.
fn at(axis: usize, centre: f32, along: f32, across: f32, y: f32) -> Vec3 {
    if axis == 0 {
        Vec3::new(along, y, centre + across)
    } else {
        Vec3::new(centre + across, y, along)
    }
}

/// Unit vectors along and across a street.
fn dirs(axis: usize) -> (Vec3, Vec3) {
    if axis == 0 {
        (Vec3::X, Vec3::Z)
    } else {
        (Vec3::Z, Vec3::X)
    }
}

/// A random point of the unit ball.
fn ball(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if v.length_squared() <= 1.0 {
            return v;
        }
    }
}

/// A random point of the unit disk.
fn disk(rng: &mut Pcg64) -> Vec2 {
    loop {
        let v = Vec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if v.length_squared() <= 1.0 {
            return v;
        }
    }
}

/// Adds items while they fit in `end` triangles: the first that would go
/// past is taken back, and so is nothing else (no item is left half made).
/// `item` returns false when it has none left.
fn fill(m: &mut Mesh, end: usize, mut item: impl FnMut(&mut Mesh) -> bool) {
    loop {
        let before = m.len();
        if !item(m) {
            return;
        }
        if m.len() > end {
            m.tris.truncate(before);
            return;
        }
    }
}

/// The smallest pitch in `min..max` at which `count` lays out at most
/// `want` items (fewer as the pitch grows): as dense as the budget allows,
/// evenly over every wall or railing rather than crowding the first ones.
fn fit_pitch(want: usize, min: f32, max: f32, count: impl Fn(f32) -> usize) -> f32 {
    if count(min) <= want {
        return min;
    }
    let (mut lo, mut hi) = (min, max);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if count(mid) <= want {
            hi = mid
        } else {
            lo = mid
        }
    }
    hi
}

/// An open room for a camera inside: floor, three walls, a wall with a
/// door, and a ceiling with a hole (light comes in): 22 triangles.
fn room(m: &mut Mesh, lo: Vec3, hi: Vec3) {
    let d = hi - lo;
    let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
    m.quad(lo + Vec3::Y * 0.02, z, x);
    m.quad(lo + z, x, y);
    m.quad(lo, y, z);
    m.quad(lo + x, z, y);
    let (door, door_height) = (1.6, 2.4);
    let left = 0.5 * (d.x - door);
    m.quad(lo, y, Vec3::X * left);
    m.quad(lo + Vec3::X * (left + door), y, Vec3::X * (d.x - left - door));
    m.quad(lo + Vec3::new(left, door_height, 0.0), Vec3::Y * (d.y - door_height), Vec3::X * door);
    // The hole is the ceiling's middle 40% each way.
    let (top, a, b) = (lo + y, 0.3 * d.x, 0.3 * d.z);
    m.quad(top, Vec3::Z * b, x);
    m.quad(top + Vec3::Z * (d.z - b), Vec3::Z * b, x);
    m.quad(top + Vec3::Z * b, Vec3::Z * (d.z - 2.0 * b), Vec3::X * a);
    m.quad(top + Vec3::new(d.x - a, 0.0, b), Vec3::Z * (d.z - 2.0 * b), Vec3::X * a);
}

/// A building's walls as (bottom corner, unit vector along, width, outward
/// normal), each seen from outside running left to right.
fn walls((lo, hi): (Vec3, Vec3)) -> [(Vec3, Vec3, f32, Vec3); 4] {
    let d = hi - lo;
    [
        (lo, Vec3::X, d.x, -Vec3::Z),
        (Vec3::new(hi.x, lo.y, lo.z), Vec3::Z, d.z, Vec3::X),
        (Vec3::new(hi.x, lo.y, hi.z), -Vec3::X, d.x, Vec3::Z),
        (Vec3::new(lo.x, lo.y, hi.z), -Vec3::Z, d.z, -Vec3::X),
    ]
}

/// Windows on every building wall in a grid of one pitch, as fine as
/// `budget` allows: a pane 3 cm off the wall (a wall is one quad, which would
/// hide a pane set into it) and a sill, 4 triangles each: small quads just
/// off large ones.
fn windows(m: &mut Mesh, layout: &Layout, budget: usize) {
    // Columns and rows a wall of width w and height h takes at pitch p:
    // the ground floor and a strip under the roof stay bare.
    let grid = |w: f32, h: f32, p: f32| (((w - 1.0) / p).max(0.0) as usize, ((h - 2.0) / (1.25 * p)).max(0.0) as usize);
    let count = |p: f32| {
        layout
            .buildings
            .iter()
            .flat_map(|&b| walls(b).map(|(_, _, w, _)| (w, b.1.y - b.0.y)))
            .map(|(w, h)| {
                let (cols, rows) = grid(w, h, p);
                cols * rows
            })
            .sum::<usize>()
    };
    let p = fit_pitch(budget / 4, 0.4, 1000.0, count);
    let (pane_w, pane_h) = (0.6 * p, 0.7 * 1.25 * p);
    for &b in &layout.buildings {
        for (o, along, w, out) in walls(b) {
            let (cols, rows) = grid(w, b.1.y - b.0.y, p);
            let x0 = 0.5 * (w - cols as f32 * p);
            for c in 0..cols {
                for r in 0..rows {
                    let centre =
                        o + along * (x0 + (c as f32 + 0.5) * p) + Vec3::Y * (1.5 + (r as f32 + 0.5) * 1.25 * p);
                    let corner = centre - along * (0.5 * pane_w) - Vec3::Y * (0.5 * pane_h);
                    m.quad(corner + out * 0.03, Vec3::Y * pane_h, along * pane_w);
                    m.quad(corner - along * (0.1 * p), along * (pane_w + 0.2 * p), out * (0.03 + 0.1 * p));
                }
            }
        }
    }
}

/// Power lines along whole streets (with half of `budget`), then railings
/// on roofs and fences around the parks with the rest: ribbons 5 mm to
/// 3 cm wide and up to 34 units long, and slivers for balusters.
fn thin(m: &mut Mesh, layout: &Layout, budget: usize, rng: &mut Pcg64) {
    let end = m.len() + budget;
    let mut streets: Vec<_> = inner_streets().collect();
    streets.shuffle(rng);
    let mut streets = streets.into_iter();
    let lines_end = m.len() + budget / 2;
    fill(m, lines_end, |m| streets.next().map(|(axis, c)| power_line(m, axis, c)).is_some());

    // Railings: each a top and a middle rail (4 triangles), then balusters
    // (2 each) as close as the rest of the budget allows.
    let mut sides: Vec<(Vec3, Vec3, f32)> = Vec::new();
    for &(lo, hi) in &layout.buildings {
        let (a, b) = (lo + Vec3::new(0.3, 0.0, 0.3), hi - Vec3::new(0.3, 0.0, 0.3));
        let y = hi.y;
        let corners = [Vec3::new(a.x, y, a.z), Vec3::new(b.x, y, a.z), Vec3::new(b.x, y, b.z), Vec3::new(a.x, y, b.z)];
        sides.extend((0..4).map(|k| (corners[k], corners[(k + 1) % 4], 1.0)));
    }
    for &park in &layout.parks {
        let (lo, hi) = (layout.blocks[park].0 + 2.0, layout.blocks[park].1 - 2.0);
        let corners = [
            Vec3::new(lo.x, KERB, lo.y),
            Vec3::new(hi.x, KERB, lo.y),
            Vec3::new(hi.x, KERB, hi.y),
            Vec3::new(lo.x, KERB, hi.y),
        ];
        sides.extend((0..4).map(|k| (corners[k], corners[(k + 1) % 4], 1.2)));
    }
    sides.shuffle(rng);
    sides.truncate((end - m.len()) / 2 / 4);
    for &(p, q, h) in &sides {
        m.quad(p + Vec3::Y * h, q - p, Vec3::Y * 0.03);
        m.quad(p + Vec3::Y * (0.5 * h), q - p, Vec3::Y * 0.03);
    }
    let balusters = |pitch: f32| sides.iter().map(|&(p, q, _)| (p.distance(q) / pitch) as usize).sum::<usize>();
    let pitch = fit_pitch((end - m.len()) / 2, 0.12, 1e4, balusters);
    for &(p, q, h) in &sides {
        let along = (q - p).normalize();
        for k in 0..(p.distance(q) / pitch) as usize {
            m.quad(p + along * ((k as f32 + 0.5) * pitch), along * 0.025, Vec3::Y * h);
        }
    }
}

/// Poles on the sidewalk at both ends of each block along a street, three
/// wires sagging between them in segments about 6 units long and 5 mm wide
/// (aspect 1000 and more): 372 triangles.
fn power_line(m: &mut Mesh, axis: usize, c: f32) {
    let side = STREET + 1.0;
    let top = KERB + 8.62;
    let poles: Vec<f32> = segments().flat_map(|(s0, s1)| [s0 + 1.0, s1 - 1.0]).collect();
    for &s in &poles {
        m.prism(at(axis, c, s, side, KERB), Vec3::Y * 9.0, 0.12, false);
        m.cuboid(at(axis, c, s - 0.06, side - 1.0, top - 0.12), at(axis, c, s + 0.06, side + 1.0, top), true);
    }
    for pair in poles.windows(2) {
        let (s, length) = (pair[0], pair[1] - pair[0]);
        let pieces = (length / 6.0).round().max(1.0) as usize;
        let sag = 0.03 * length;
        for offset in [-0.8, 0.0, 0.8] {
            let point = |i: usize| {
                let t = i as f32 / pieces as f32;
                at(axis, c, s + t * length, side + offset, top - sag * 4.0 * t * (1.0 - t))
            };
            for i in 0..pieces {
                let (a, b) = (point(i), point(i + 1));
                m.quad(a, b - a, Vec3::Y * 0.005);
            }
        }
    }
}

/// Small boxes and prisms: a table in each room, cars in shuffled lane
/// slots (to 45% of `budget`), benches (to 65%), bollards (to 80%), and
/// rooftop units to the end.
fn details(m: &mut Mesh, layout: &Layout, budget: usize, rng: &mut Pcg64) {
    let (start, end) = (m.len(), m.len() + budget);
    let mut rooms = layout.rooms.iter();
    fill(m, end, |m| rooms.next().map(|&(lo, hi)| table(m, (0.5 * (lo + hi)).with_y(lo.y + 0.02))).is_some());

    let mut slots = Vec::new();
    for (axis, c) in inner_streets() {
        for (s0, s1) in segments() {
            let mut s = s0 + 3.0;
            while s + 3.0 <= s1 {
                slots.extend([-4.6, -1.8, 1.8, 4.6].map(|lane| (axis, c, s, lane)));
                s += 6.5;
            }
        }
    }
    slots.shuffle(rng);
    let mut slots = slots.into_iter();
    // Each kind's end, cumulative: what one leaves, the next may take.
    let share = |percent: usize| start + budget * percent / 100;
    fill(m, share(45), |m| slots.next().map(|(axis, c, s, lane)| car(m, rng, axis, c, s, lane)).is_some());
    fill(m, share(65), |m| {
        let spot = if rng.random_bool(0.5) { layout.park_spot(rng, 2.5) } else { layout.sidewalk_spot(rng, 1.2) };
        bench(m, Vec3::new(spot.x, KERB, spot.y), rng.random_bool(0.5));
        true
    });
    fill(m, share(80), |m| {
        let spot = layout.sidewalk_spot(rng, 0.4);
        m.prism(Vec3::new(spot.x, KERB, spot.y), Vec3::Y * 0.9, 0.1, true);
        true
    });
    fill(m, end, |m| {
        let (lo, hi) = layout.buildings[rng.random_range(0..layout.buildings.len())];
        let size = Vec3::new(rng.random_range(0.5..2.0), rng.random_range(0.4..1.5), rng.random_range(0.5..2.0));
        let x = rng.random_range(lo.x + 0.3..hi.x - 0.3 - size.x);
        let z = rng.random_range(lo.z + 0.3..hi.z - 0.3 - size.z);
        m.cuboid(Vec3::new(x, hi.y, z), Vec3::new(x, hi.y, z) + size, false);
        true
    });
    debug_assert!(m.len() - start <= budget);
}

/// A table standing at `floor`: a top and four legs, 50 triangles.
fn table(m: &mut Mesh, floor: Vec3) {
    m.cuboid(floor + Vec3::new(-1.0, 0.72, -0.5), floor + Vec3::new(1.0, 0.78, 0.5), false);
    for (x, z) in [(-0.9, -0.4), (0.9, -0.4), (-0.9, 0.4), (0.9, 0.4)] {
        m.cuboid(floor + Vec3::new(x - 0.03, 0.0, z - 0.03), floor + Vec3::new(x + 0.03, 0.72, z + 0.03), false);
    }
}

/// A car along a street: body, cabin and four hexagonal wheels, 102
/// triangles.
fn car(m: &mut Mesh, rng: &mut Pcg64, axis: usize, c: f32, s: f32, lane: f32) {
    let (_, across) = dirs(axis);
    let length: f32 = rng.random_range(3.8..4.8);
    let half = 0.5 * length;
    m.cuboid(at(axis, c, s - half, lane - 0.9, 0.3), at(axis, c, s + half, lane + 0.9, 1.1), true);
    m.cuboid(at(axis, c, s - 0.3 * length, lane - 0.8, 1.1), at(axis, c, s + 0.2 * length, lane + 0.8, 1.65), false);
    for wheel in [-0.32, 0.32] {
        for side in [-0.95, 0.7] {
            m.prism(at(axis, c, s + wheel * length, lane + side, 0.33), across * 0.25, 0.33, true);
        }
    }
}

/// A bench at `ground` (turned a quarter when `turn`): seat, back and two
/// legs, 40 triangles.
fn bench(m: &mut Mesh, ground: Vec3, turn: bool) {
    let mut part = |(u0, u1): (f32, f32), (v0, v1): (f32, f32), (y0, y1): (f32, f32)| {
        let (lo, hi) = if turn {
            (Vec3::new(v0, y0, u0), Vec3::new(v1, y1, u1))
        } else {
            (Vec3::new(u0, y0, v0), Vec3::new(u1, y1, v1))
        };
        m.cuboid(ground + lo, ground + hi, false);
    };
    part((-0.8, 0.8), (-0.22, 0.22), (0.42, 0.48));
    part((-0.8, 0.8), (0.17, 0.23), (0.48, 0.9));
    part((-0.73, -0.67), (-0.2, 0.2), (0.0, 0.42));
    part((0.67, 0.73), (-0.2, 0.2), (0.0, 0.42));
}

/// Dashed centre lines and zebra crossings on the inner streets, as many
/// (shuffled) as `budget` allows.
fn markings(m: &mut Mesh, budget: usize, rng: &mut Pcg64) {
    let y = 0.01;
    let mut stripes = Vec::new();
    for (axis, c) in inner_streets() {
        let (along, across) = dirs(axis);
        for (s0, s1) in segments() {
            let mut s = s0 + 1.5;
            while s + 3.0 <= s1 {
                stripes.push((at(axis, c, s, -0.075, y), along * 3.0, across * 0.15));
                s += 6.0;
            }
        }
        for crossing in (1..BLOCKS).map(|k| k as f32 * PITCH - HALF) {
            for start in [crossing - STREET - 3.5, crossing + STREET + 0.5] {
                for k in 0..8 {
                    stripes.push((at(axis, c, start, -5.3 + 1.5 * k as f32, y), along * 3.0, across * 0.7));
                }
            }
        }
    }
    stripes.shuffle(rng);
    stripes.truncate(budget / 2);
    for (o, u, v) in stripes {
        m.quad(o, v, u);
    }
}

/// Trees in the parks and along the sidewalks: a hexagonal trunk (12
/// triangles) under a crown of tiny leaves at random orientations, hundreds
/// a tree from N of about 100 000 (both counts grow as √budget).
fn trees(m: &mut Mesh, layout: &Layout, budget: usize, rng: &mut Pcg64) {
    const TRUNK: usize = 12;
    if budget <= TRUNK {
        return;
    }
    let count = (((budget as f64).sqrt() / 2.0) as usize).clamp(1, budget / (TRUNK + 1));
    let leaves = budget / count - TRUNK;
    for k in 0..count {
        let spot = if k % 2 == 0 { layout.park_spot(rng, 2.0) } else { layout.sidewalk_spot(rng, 1.5) };
        let base = Vec3::new(spot.x, KERB, spot.y);
        let height = rng.random_range(2.5..4.5);
        m.prism(base, Vec3::Y * height, rng.random_range(0.15..0.3), false);
        let radius = rng.random_range(1.5..3.2);
        let crown = base + Vec3::Y * (height + 0.6 * radius);
        for _ in 0..leaves {
            let p = crown + ball(rng) * Vec3::new(radius, 0.8 * radius, radius);
            let size = rng.random_range(0.06..0.18);
            // Edges far enough from parallel that no leaf is a needle.
            let (e1, e2) = loop {
                let (a, b) = (ball(rng), ball(rng));
                if a.cross(b).length() > 0.2 {
                    break (a, b);
                }
            };
            m.tri(p, p + e1 * size, p + e2 * size);
        }
    }
}

/// `count` blades of grass in patches of the parks: slivers 8 to 20 mm at
/// the base, 15 to 60 cm tall, leaning every way.
fn grass(m: &mut Mesh, layout: &Layout, count: usize, rng: &mut Pcg64) {
    if count == 0 {
        return;
    }
    let patches: Vec<(Vec2, f32)> =
        (0..(count / 20_000).clamp(1, 8)).map(|_| (layout.park_spot(rng, 7.0), rng.random_range(3.0..6.0))).collect();
    for k in 0..count {
        let (centre, radius) = patches[k % patches.len()];
        let p = centre + disk(rng) * radius;
        let base = Vec3::new(p.x, KERB, p.y);
        let side = loop {
            let d = disk(rng);
            if d.length_squared() > 0.01 {
                break d.normalize();
            }
        };
        let half = Vec3::new(side.x, 0.0, side.y) * rng.random_range(0.004..0.01);
        let height = rng.random_range(0.15..0.6);
        let lean = disk(rng) * (0.3 * height);
        m.tri(base - half, base + half, base + Vec3::new(lean.x, height, lean.y));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The corners in f64.
    fn corners(t: &Triangle) -> [[f64; 3]; 3] {
        [t.v0, t.v1, t.v2].map(|p| p.map(f64::from))
    }

    fn sub(p: [f64; 3], q: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| p[k] - q[k])
    }

    fn length(v: [f64; 3]) -> f64 {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// Area from the f32 corners, in f64 (exact enough to tell zero).
    fn area(t: &Triangle) -> f64 {
        let [a, b, c] = corners(t);
        let (u, v) = (sub(b, a), sub(c, a));
        length([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]) / 2.0
    }

    #[test]
    fn city_is_deterministic() {
        let a = city(20_000, 7);
        assert_eq!(a, city(20_000, 7));
        assert_ne!(a, city(20_000, 8));
    }

    #[test]
    fn city_has_about_n_triangles() {
        for n in [1000, 100_000] {
            let len = city(n, 1).len();
            assert!(len.abs_diff(n) * 20 <= n, "city:{n}: {len} triangles");
        }
        // The layout whatever N: a few hundred triangles.
        assert!(city(1, 1).len() >= 300);
    }

    #[test]
    fn city_triangles_are_finite_and_not_degenerate() {
        for seed in [1, 2] {
            for (i, t) in city(100_000, seed).iter().enumerate() {
                assert!([t.v0, t.v1, t.v2].iter().flatten().all(|x| x.is_finite()), "triangle {i}: {t:?}");
                assert!(area(t) > 0.0, "triangle {i} has no area: {t:?}");
            }
        }
    }

    /// Areas span six orders of magnitude and more, most triangles small and
    /// a few huge; prints each kind's count (`--nocapture`).
    #[test]
    fn city_areas_span_many_orders() {
        let m = build(100_000, 1);
        let mut start = 0;
        for &(name, end) in &m.parts {
            println!("{name}: {}", end - start);
            start = end;
        }
        let mut areas: Vec<f64> = m.tris.iter().map(area).collect();
        areas.sort_by(f64::total_cmp);
        let (min, max, median) = (areas[0], areas[areas.len() - 1], areas[areas.len() / 2]);
        println!("area {min:e} .. {max:e}, median {median:e}, span {:e}", max / min);
        assert!(max / min >= 1e6, "span {}", max / min);
        assert!(median < 1e-5 * max, "median {median}, max {max}");
    }

    /// Some triangles are needles (aspect 1000 and more, the longest edge
    /// over the height on it).
    #[test]
    fn city_has_needles() {
        let aspect = |t: &Triangle| {
            let [a, b, c] = corners(t);
            let longest = length(sub(b, a)).max(length(sub(c, b))).max(length(sub(a, c)));
            longest * longest / (2.0 * area(t))
        };
        let needles = city(100_000, 1).iter().filter(|t| aspect(t) >= 1000.0).count();
        assert!(needles >= 100, "{needles} needles");
    }
}
