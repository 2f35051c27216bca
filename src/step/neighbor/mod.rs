//! Verlet pair list with a skin, built on a cell grid with periodic images.
//!
//! At every build the particles are re-ordered in memory by cell, the slowest axis a walled
//! (non-periodic) one where there is one, so that a thread owning a contiguous range of them owns
//! a slab of space with as few faces shared with other threads as the box allows (one in the
//! shear case: the slabs are stacked between the walls) and touches few particles of theirs. The order of floating-point sums never depends on that memory order: each pair is
//! oriented by original ids (P = lower id), and each particle's list of pairs is sorted by its
//! partners' original ids.

pub mod rebuild;

use crate::case::Search;
use crate::state::Domain;
use crate::Vec3;

/// The pair list, in memory indices. Pair `k` joins `p[k]` and `i[k]` with
/// `id[p[k]] < id[i[k]]`; as built, pairs are grouped by their lower memory index (`owner`),
/// increasing (the simulation then re-sorts them within each thread's share).
#[derive(Clone, Debug, Default)]
pub struct PairList {
    /// Memory index of the lower-id particle of each pair (P).
    pub p: Vec<u32>,
    /// Memory index of the higher-id particle of each pair (I).
    pub i: Vec<u32>,
    /// `adj[adj_start[a]..adj_start[a+1]]` are particle `a`'s pair slots, sorted by partner id;
    /// each entry is `slot << 1 | role`, role 0 when `a` is P and 1 when `a` is I.
    pub adj_start: Vec<u32>,
    pub adj: Vec<u32>,
    /// Scratch of [`PairList::index`]: `(particle, entry)` in the order of partner ids.
    by_partner: Vec<(u32, u32)>,
}

/// The cells `lo..hi` of a half stencil; `wraps` when the separation of a particle of the
/// stencil's cell from one of these may need its minimum image: one of them is reached across a
/// periodic face, or a periodic axis has too few cells for two neighbours to be surely within
/// half a period.
#[derive(Clone, Copy, Debug)]
struct Run {
    lo: u32,
    hi: u32,
    wraps: bool,
}

/// Builder of pair lists; keeps its scratch buffers between builds.
#[derive(Clone, Debug)]
pub struct NeighborBuilder {
    /// Skin added to r_P + r_I (length).
    pub skin: f64,
    /// Edge of a cell; ≥ 2 r_max + skin (length).
    pub cell: f64,
    pub search: Search,
    /// Cell of each particle at the last [`NeighborBuilder::order`] or `prepare`.
    cells: Vec<u32>,
    cell_start: Vec<u32>,
    /// Scratch of the counting sort: the memory index of each id, and each cell's next slot.
    by_id: Vec<u32>,
    fill: Vec<u32>,
    /// Half stencils of the grid they were made for, as runs of consecutive cells: the runs
    /// `stencil[j]` for `j` in `stencil_start[c]..stencil_start[c + 1]` hold the distinct cells
    /// adjacent to (or equal to) cell `c`, less the runs that lie wholly below `c`, in
    /// increasing order. The grid depends on the box alone, so they are made once.
    stencil: Vec<Run>,
    stencil_start: Vec<u32>,
    stencil_grid: Option<([usize; 3], [usize; 3], [bool; 3])>,
}

impl NeighborBuilder {
    /// A builder for particles of maximal radius `r_max`. `cell` below 2 r_max + skin is raised
    /// to that value.
    pub fn new(skin: f64, cell: f64, r_max: f64, search: Search) -> Self {
        NeighborBuilder {
            skin,
            cell: cell.max(2.0 * r_max + skin),
            search,
            cells: Vec::new(),
            cell_start: Vec::new(),
            by_id: Vec::new(),
            fill: Vec::new(),
            stencil: Vec::new(),
            stencil_start: Vec::new(),
            stencil_grid: None,
        }
    }

    /// The memory order for positions `x` with original indices `id` (a permutation of
    /// `0..x.len()`): indices sorted by (cell, id), cells in the grid's axis order (a walled axis
    /// slowest). `order[new] = old`. It also prepares the builder for the positions in that
    /// order, as [`NeighborBuilder::prepare`] would once the caller has re-ordered them, so that
    /// [`NeighborBuilder::search`] may follow.
    pub fn order(&mut self, domain: &Domain, x: &[Vec3], id: &[u32], order: &mut Vec<u32>) {
        let grid = Grid::new(domain, self.cell);
        self.count_cells(&grid, domain, x);
        // A counting sort by cell, stable, over the particles taken in id order: each cell's
        // particles come out by id.
        self.by_id.clear();
        self.by_id.resize(x.len(), 0);
        for (a, &i) in id.iter().enumerate() {
            self.by_id[i as usize] = a as u32;
        }
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start);
        order.clear();
        order.resize(x.len(), 0);
        for &a in &self.by_id {
            let at = &mut self.fill[self.cells[a as usize] as usize];
            order[*at as usize] = a;
            *at += 1;
        }
        self.make_stencils(&grid);
    }

    /// Rebuilds the pairs of `list` for particles already in [`NeighborBuilder::order`]'s
    /// order, grouped by owner; the per-particle lists are made by [`PairList::index`] once the
    /// caller has settled the pairs' order. A pair enters when |x_P − x_I| < r_P + r_I + skin and
    /// `interacts(a, b)` (wall–wall pairs never do). The same as [`NeighborBuilder::prepare`]
    /// and one [`NeighborBuilder::search`] over all owners.
    pub fn build(
        &mut self,
        list: &mut PairList,
        domain: &Domain,
        x: &[Vec3],
        radius: &[f64],
        id: &[u32],
        interacts: impl Fn(usize, usize) -> bool,
    ) {
        self.prepare(domain, x);
        list.p.clear();
        list.i.clear();
        let found = (&mut list.p, &mut list.i);
        self.search(domain, x, radius, id, 0..x.len(), interacts, found);
    }

    /// Locates the particles `x` (in [`NeighborBuilder::order`]'s order) in the cells, for the
    /// searches that follow.
    pub fn prepare(&mut self, domain: &Domain, x: &[Vec3]) {
        if self.search == Search::AllPairs {
            return;
        }
        let grid = Grid::new(domain, self.cell);
        self.count_cells(&grid, domain, x);
        self.make_stencils(&grid);
    }

    /// The cell of each particle, and `cell_start`: the particles of cell `c`, once sorted by
    /// cell, are `cell_start[c]..cell_start[c + 1]`.
    fn count_cells(&mut self, grid: &Grid, domain: &Domain, x: &[Vec3]) {
        self.cells.clear();
        self.cells
            .extend(x.iter().map(|p| grid.index(grid.coords(domain, p)) as u32));
        self.cell_start.clear();
        self.cell_start.resize(grid.count() + 1, 0);
        for &c in &self.cells {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..grid.count() {
            self.cell_start[c + 1] += self.cell_start[c];
        }
    }

    /// Appends to `found` (P, I memory indices) the pairs owned by the particles `owners`, the
    /// owner of a pair being its particle of lower memory index, in the order of owners and then
    /// of partners; the searches of consecutive owner ranges, concatenated, give one search of
    /// their union. Needs [`NeighborBuilder::prepare`] for the same `x`.
    #[allow(clippy::too_many_arguments)]
    pub fn search(
        &self,
        domain: &Domain,
        x: &[Vec3],
        radius: &[f64],
        id: &[u32],
        owners: std::ops::Range<usize>,
        interacts: impl Fn(usize, usize) -> bool,
        found: (&mut Vec<u32>, &mut Vec<u32>),
    ) {
        let (found_p, found_i) = found;
        let skin = self.skin;
        // Particle `a` against the particles `from..to`: a pair enters when
        // |x_a − x_b| < r_a + r_b + skin (the minimum image with `wraps`; without, the direct
        // separation is its own minimum image, bit for bit) and `interacts(a, b)`.
        let mut scan = |a: usize, from: usize, to: usize, wraps: bool| {
            let (xa, ra, to) = (x[a], radius[a], to.max(from));
            for (b, (xb, rb)) in (from..to).zip(x[from..to].iter().zip(&radius[from..to])) {
                let cut = ra + rb + skin;
                let d = if wraps {
                    domain.min_image(xa - xb)
                } else {
                    xa - xb
                };
                if d.norm_squared() < cut * cut && interacts(a, b) {
                    let (p, i) = if id[a] < id[b] { (a, b) } else { (b, a) };
                    found_p.push(p as u32);
                    found_i.push(i as u32);
                }
            }
        };
        match self.search {
            Search::AllPairs => {
                for a in owners {
                    scan(a, a + 1, x.len(), true);
                }
            }
            Search::Cells => {
                let cells = self.cell_start.len() - 1;
                let first = self
                    .cell_start
                    .partition_point(|&s| s as usize <= owners.start);
                for c in first.saturating_sub(1)..cells {
                    let (s, e) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
                    if s >= owners.end {
                        break;
                    }
                    let near = &self.stencil
                        [self.stencil_start[c] as usize..self.stencil_start[c + 1] as usize];
                    // Cells in index order hold increasing memory indices: each particle's
                    // partners come out sorted (and those in cells below c are lower).
                    for a in s.max(owners.start)..e.min(owners.end) {
                        for run in near {
                            let (s, e) = (
                                self.cell_start[run.lo as usize] as usize,
                                self.cell_start[run.hi as usize] as usize,
                            );
                            scan(a, s.max(a + 1), e, run.wraps);
                        }
                    }
                }
            }
        }
    }

    /// Makes the half stencils of `grid` unless they are those of the last build.
    fn make_stencils(&mut self, grid: &Grid) {
        if self.stencil_grid == Some((grid.n, grid.axes, grid.periodic)) {
            return;
        }
        self.stencil.clear();
        self.stencil_start.clear();
        self.stencil_start.push(0);
        let mut near = Vec::with_capacity(27);
        for c in 0..grid.count() {
            near.clear();
            grid.for_each_neighbour(grid.cell_coords(c), |nc, wraps| {
                near.push((nc as u32, wraps))
            });
            near.sort_unstable();
            // Cells adjacent along the fastest axis have consecutive indices: one run each.
            let start = self.stencil.len();
            for &(nc, wraps) in &near {
                match self.stencil[start..].last_mut() {
                    Some(run) if run.hi == nc => {
                        run.hi = nc + 1;
                        run.wraps |= wraps;
                    }
                    _ => self.stencil.push(Run {
                        lo: nc,
                        hi: nc + 1,
                        wraps,
                    }),
                }
            }
            let mut kept = start;
            for j in start..self.stencil.len() {
                if self.stencil[j].hi as usize > c {
                    self.stencil[kept] = self.stencil[j];
                    kept += 1;
                }
            }
            self.stencil.truncate(kept);
            self.stencil_start.push(self.stencil.len() as u32);
        }
        self.stencil_grid = Some((grid.n, grid.axes, grid.periodic));
    }
}

impl PairList {
    /// Fills the per-particle slot lists of `n` particles, each sorted by the partners'
    /// original ids `id`; `fill` is scratch.
    pub fn index(&mut self, n: usize, id: &[u32], fill: &mut Vec<u32>) {
        build_adjacency(self, n, id, fill);
    }
}

fn build_adjacency(list: &mut PairList, n: usize, id: &[u32], fill: &mut Vec<u32>) {
    list.adj_start.clear();
    list.adj_start.resize(n + 1, 0);
    for k in 0..list.p.len() {
        list.adj_start[list.p[k] as usize + 1] += 1;
        list.adj_start[list.i[k] as usize + 1] += 1;
    }
    for a in 0..n {
        list.adj_start[a + 1] += list.adj_start[a];
    }
    list.adj.clear();
    list.adj.resize(list.adj_start[n] as usize, 0);
    // Two stable counting sorts: every entry by its partner's id, then by its particle, so that
    // each particle's entries come out in the order of partner ids.
    fill.clear();
    fill.resize(n + 1, 0);
    for k in 0..list.p.len() {
        for q in [list.p[k], list.i[k]] {
            fill[id[q as usize] as usize + 1] += 1;
        }
    }
    for a in 0..n {
        fill[a + 1] += fill[a];
    }
    list.by_partner.clear();
    list.by_partner.resize(list.adj.len(), (0, 0));
    for k in 0..list.p.len() {
        let (p, i) = (list.p[k], list.i[k]);
        for (a, partner, role) in [(p, i, 0), (i, p, 1)] {
            let at = &mut fill[id[partner as usize] as usize];
            list.by_partner[*at as usize] = (a, ((k as u32) << 1) | role);
            *at += 1;
        }
    }
    fill.clear();
    fill.extend_from_slice(&list.adj_start[..n]);
    for &(a, entry) in &list.by_partner {
        list.adj[fill[a as usize] as usize] = entry;
        fill[a as usize] += 1;
    }
}

/// Cell grid over the box; periodic axes wrap, others clamp. Cell index runs over `axes`,
/// slowest first: the longest non-periodic axis, if any, then the others in x, y, z order.
struct Grid {
    n: [usize; 3],
    axes: [usize; 3],
    inv_edge: [f64; 3],
    periodic: [bool; 3],
}

impl Grid {
    fn new(domain: &Domain, cell: f64) -> Self {
        let l = domain.lengths();
        let mut n = [1usize; 3];
        let mut inv_edge = [0.0; 3];
        for k in 0..3 {
            n[k] = ((l[k] / cell).floor() as usize).max(1);
            inv_edge[k] = n[k] as f64 / l[k];
        }
        let walled = (0..3)
            .filter(|&k| !domain.periodic[k])
            .max_by(|&a, &b| l[a].total_cmp(&l[b]).then(b.cmp(&a)));
        let slow = walled.unwrap_or(0);
        let mut rest = (0..3).filter(|&k| k != slow);
        let axes = [slow, rest.next().unwrap(), rest.next().unwrap()];
        Grid {
            n,
            axes,
            inv_edge,
            periodic: domain.periodic,
        }
    }

    fn count(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    /// Coordinates of the cell of index `index` (the inverse of [`Grid::index`]).
    fn cell_coords(&self, index: usize) -> [usize; 3] {
        let [a, b, d] = self.axes;
        let mut c = [0; 3];
        c[d] = index % self.n[d];
        c[b] = index / self.n[d] % self.n[b];
        c[a] = index / self.n[d] / self.n[b];
        c
    }

    /// The cell of position `x`, per axis; positions outside the box go to the nearest cell.
    fn coords(&self, domain: &Domain, x: &Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for k in 0..3 {
            // The cast truncates (floor for f ≥ 0) and sends negatives and NaN to 0, without
            // the call to libm's floor that the baseline x86-64 target makes.
            let f = (x[k] - domain.lo[k]) * self.inv_edge[k];
            c[k] = (f as usize).min(self.n[k] - 1);
        }
        c
    }

    fn index(&self, c: [usize; 3]) -> usize {
        let [a, b, d] = self.axes;
        (c[a] * self.n[b] + c[b]) * self.n[d] + c[d]
    }

    /// Calls `f` once for each distinct cell adjacent to (or equal to) cell `c`, with whether
    /// a separation between the two cells may need its minimum image: the cell is reached
    /// across a periodic face, or a periodic axis has fewer than 5 cells. With 5 or more, two
    /// particles in cells adjacent without a wrap are at most 2/5 of the period apart along
    /// that axis (a particle wrapped onto the box's far face lies within round-off of its cell),
    /// so `Domain::min_image` shifts nothing.
    fn for_each_neighbour(&self, c: [usize; 3], mut f: impl FnMut(usize, bool)) {
        let mut axis = [[(0usize, false); 3]; 3];
        let mut len = [0usize; 3];
        for k in 0..3 {
            let m = self.n[k] as i64;
            for d in -1i64..=1 {
                let v = c[k] as i64 + d;
                let outside = v < 0 || v >= m;
                let v = if self.periodic[k] {
                    v.rem_euclid(m)
                } else if outside {
                    continue;
                } else {
                    v
                } as usize;
                let wraps = self.periodic[k] && (outside || m < 5);
                if !axis[k][..len[k]].iter().any(|&(u, _)| u == v) {
                    axis[k][len[k]] = (v, wraps);
                    len[k] += 1;
                }
            }
        }
        for &(cx, wx) in &axis[0][..len[0]] {
            for &(cy, wy) in &axis[1][..len[1]] {
                for &(cz, wz) in &axis[2][..len[2]] {
                    f(self.index([cx, cy, cz]), wx || wy || wz);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_scene(n: usize, seed: u64) -> (Domain, Vec<Vec3>, Vec<f64>, Vec<u32>) {
        let domain = Domain::new(Vec3::zeros(), Vec3::new(6.0, 4.0, 7.0), [true, true, false]);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let x = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.gen_range(0.0..6.0),
                    rng.gen_range(0.0..4.0),
                    rng.gen_range(0.0..7.0),
                )
            })
            .collect();
        (domain, x, vec![0.5; n], (0..n as u32).collect())
    }

    fn sorted_id_pairs(l: &PairList, id: &[u32]) -> Vec<(u32, u32)> {
        let mut v: Vec<(u32, u32)> = (0..l.p.len())
            .map(|k| (id[l.p[k] as usize], id[l.i[k] as usize]))
            .collect();
        v.sort_unstable();
        v
    }

    /// The cell search on `x` in cell order, and the all-pairs search on `x` as given: the
    /// builder, the ordered positions and ids, and both lists.
    struct Searched {
        builder: NeighborBuilder,
        xs: Vec<Vec3>,
        ids: Vec<u32>,
        cells: PairList,
        all: PairList,
    }

    fn search_both(domain: &Domain, x: &[Vec3], r: &[f64], id: &[u32], skin: f64) -> Searched {
        let mut builder = NeighborBuilder::new(skin, 0.0, r[0], Search::Cells);
        let mut order = Vec::new();
        builder.order(domain, x, id, &mut order);
        let xs: Vec<Vec3> = order.iter().map(|&o| x[o as usize]).collect();
        let ids: Vec<u32> = order.iter().map(|&o| id[o as usize]).collect();
        let mut cells = PairList::default();
        builder.build(&mut cells, domain, &xs, r, &ids, |_, _| true);
        let mut all = PairList::default();
        NeighborBuilder::new(skin, 0.0, r[0], Search::AllPairs).build(
            &mut all,
            domain,
            x,
            r,
            id,
            |_, _| true,
        );
        Searched {
            builder,
            xs,
            ids,
            cells,
            all,
        }
    }

    #[test]
    fn cell_search_finds_exactly_the_all_pairs_list_with_pairs_oriented_by_id() {
        let (domain, x, r, id) = random_scene(300, 7);
        let Searched {
            ids, cells, all, ..
        } = search_both(&domain, &x, &r, &id, 0.3);
        assert!(!cells.p.is_empty());
        assert_eq!(sorted_id_pairs(&cells, &ids), sorted_id_pairs(&all, &id));
        assert!((0..cells.p.len()).all(|k| ids[cells.p[k] as usize] < ids[cells.i[k] as usize]));
    }

    proptest::proptest! {
        /// Boxes of one to five cells a side, any axis periodic or walled: the runs of the half
        /// stencils (including those that wrap, and grids too small for 27 distinct cells) miss
        /// no pair and list none twice, and a search split between owner ranges finds the same
        /// pairs in the same order.
        #[test]
        fn cell_search_equals_all_pairs_on_any_grid(
            lengths in proptest::array::uniform3(1.0f64..7.0),
            periodic in proptest::array::uniform3(proptest::bool::ANY),
            n in 1usize..120,
            seed in 0u64..1000,
            split in 0.0f64..1.0,
        ) {
            let domain = Domain::new(Vec3::zeros(), Vec3::from(lengths), periodic);
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let x: Vec<Vec3> = (0..n)
                .map(|_| Vec3::from(std::array::from_fn(|k| rng.gen_range(0.0..lengths[k]))))
                .collect();
            let r = vec![0.3; n];
            let id: Vec<u32> = (0..n as u32).collect();
            let Searched { builder: b, xs, ids, cells, all } = search_both(&domain, &x, &r, &id, 0.1);
            proptest::prop_assert_eq!(sorted_id_pairs(&cells, &ids), sorted_id_pairs(&all, &id));
            // two searches over consecutive owner ranges, concatenated, are the one search
            let m = (split * n as f64) as usize;
            let (mut p, mut i) = (Vec::new(), Vec::new());
            for owners in [0..m, m..n] {
                b.search(&domain, &xs, &r, &ids, owners, |_, _| true, (&mut p, &mut i));
            }
            proptest::prop_assert_eq!((p, i), (cells.p, cells.i));
        }
    }

    proptest::proptest! {
        /// The counting sort gives the order by (cell, id) whatever the ids, and leaves the
        /// builder ready to search the re-ordered positions: the same pairs as a full build.
        #[test]
        fn order_sorts_by_cell_then_id_and_prepares_the_search(
            n in 1usize..300,
            seed in 0u64..1000,
            skin in 0.05f64..0.6,
        ) {
            let (domain, x, r, _) = random_scene(n, seed);
            let id: Vec<u32> = (0..n as u32).map(|a| (a * 7919) % n as u32).collect();
            let mut b = NeighborBuilder::new(skin, 0.0, 0.5, Search::Cells);
            let mut order = Vec::new();
            b.order(&domain, &x, &id, &mut order);
            let grid = Grid::new(&domain, b.cell);
            let key = |a: usize| (grid.index(grid.coords(&domain, &x[a])), id[a]);
            let mut expected: Vec<u32> = (0..n as u32).collect();
            expected.sort_by_key(|&a| key(a as usize));
            proptest::prop_assert_eq!(&order, &expected);
            let xs: Vec<Vec3> = order.iter().map(|&o| x[o as usize]).collect();
            let ids: Vec<u32> = order.iter().map(|&o| id[o as usize]).collect();
            let (mut p, mut i) = (Vec::new(), Vec::new());
            b.search(&domain, &xs, &r, &ids, 0..n, |_, _| true, (&mut p, &mut i));
            let mut built = PairList::default();
            b.build(&mut built, &domain, &xs, &r, &ids, |_, _| true);
            proptest::prop_assert_eq!((p, i), (built.p, built.i));
        }
    }

    #[test]
    fn adjacency_lists_are_sorted_by_partner_id() {
        let (domain, x, r, _) = random_scene(200, 3);
        // a scrambled id assignment: memory order is not id order
        let id: Vec<u32> = (0..200u32).map(|a| (a * 77) % 200).collect();
        let mut b = NeighborBuilder::new(0.5, 0.0, 0.5, Search::Cells);
        let mut order = Vec::new();
        b.order(&domain, &x, &id, &mut order);
        let x: Vec<Vec3> = order.iter().map(|&o| x[o as usize]).collect();
        let id: Vec<u32> = order.iter().map(|&o| id[o as usize]).collect();
        let mut l = PairList::default();
        b.build(&mut l, &domain, &x, &r, &id, |_, _| true);
        l.index(x.len(), &id, &mut Vec::new());
        for a in 0..x.len() {
            let partners: Vec<u32> = l.adj[l.adj_start[a] as usize..l.adj_start[a + 1] as usize]
                .iter()
                .map(|&e| {
                    let k = (e >> 1) as usize;
                    id[if e & 1 == 0 { l.i[k] } else { l.p[k] } as usize]
                })
                .collect();
            assert!(partners.windows(2).all(|w| w[0] < w[1]), "particle {a}");
        }
    }
}
