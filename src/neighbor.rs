//! Verlet pair list with a skin, built on a cell grid with periodic images; pairs in canonical
//! order (sorted by lower index, then higher index), and for each particle the list of its
//! pair slots sorted by partner id, which fixes the order in which its forces are summed.

use crate::domain::Domain;
use crate::Vec3;

/// How candidate pairs are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Cell grid of edge ≥ 2 r_max + skin (the default).
    Cells,
    /// Every pair is tested (O(N²); a reference for tests).
    AllPairs,
}

/// The pair list. Pair `k` joins `p[k] < i[k]`; pairs are sorted by `(p, i)`.
#[derive(Clone, Debug, Default)]
pub struct PairList {
    /// Lower index of each pair (P).
    pub p: Vec<u32>,
    /// Higher index of each pair (I).
    pub i: Vec<u32>,
    /// `adj[adj_start[a]..adj_start[a+1]]` are particle `a`'s pair slots, sorted by partner id;
    /// each entry is `slot << 1 | role`, role 0 when `a` is P and 1 when `a` is I.
    pub adj_start: Vec<u32>,
    pub adj: Vec<u32>,
}

/// Builder of pair lists; keeps its scratch buffers between builds.
#[derive(Clone, Debug)]
pub struct NeighborBuilder {
    /// Skin added to r_P + r_I (length).
    pub skin: f64,
    /// Edge of a cell; ≥ 2 r_max + skin (length).
    pub cell: f64,
    pub search: Search,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    cell_of: Vec<u32>,
    fill: Vec<u32>,
    partners: Vec<u32>,
}

impl NeighborBuilder {
    /// A builder for particles of maximal radius `r_max`. `cell` below 2 r_max + skin is raised
    /// to that value.
    pub fn new(skin: f64, cell: f64, r_max: f64, search: Search) -> Self {
        NeighborBuilder {
            skin,
            cell: cell.max(2.0 * r_max + skin),
            search,
            cell_start: Vec::new(),
            cell_items: Vec::new(),
            cell_of: Vec::new(),
            fill: Vec::new(),
            partners: Vec::new(),
        }
    }

    /// Rebuilds `list` for positions `x` and radii `radius`; `interacts(a, b)` excludes pairs
    /// that never interact (wall–wall). A pair enters when |x_P − x_I| < r_P + r_I + skin.
    pub fn build(
        &mut self,
        list: &mut PairList,
        domain: &Domain,
        x: &[Vec3],
        radius: &[f64],
        interacts: impl Fn(usize, usize) -> bool,
    ) {
        let n = x.len();
        list.p.clear();
        list.i.clear();
        let skin = self.skin;
        let accept = |a: usize, b: usize| {
            let cut = radius[a] + radius[b] + skin;
            interacts(a, b) && domain.min_image(x[a] - x[b]).norm_squared() < cut * cut
        };
        match self.search {
            Search::AllPairs => {
                for a in 0..n {
                    for b in a + 1..n {
                        if accept(a, b) {
                            list.p.push(a as u32);
                            list.i.push(b as u32);
                        }
                    }
                }
            }
            Search::Cells => {
                let grid = Grid::new(domain, self.cell);
                self.bin(&grid, domain, x);
                let mut partners = std::mem::take(&mut self.partners);
                for a in 0..n {
                    partners.clear();
                    let c = grid.coords(domain, &x[a]);
                    for nc in grid.neighbours(c) {
                        let (s, e) = (self.cell_start[nc], self.cell_start[nc + 1]);
                        for &b in &self.cell_items[s as usize..e as usize] {
                            if b as usize > a && accept(a, b as usize) {
                                partners.push(b);
                            }
                        }
                    }
                    partners.sort_unstable();
                    for &b in &partners {
                        list.p.push(a as u32);
                        list.i.push(b);
                    }
                }
                self.partners = partners;
            }
        }
        build_adjacency(list, n, &mut self.fill);
    }

    /// Counting sort of particle indices into cells.
    fn bin(&mut self, grid: &Grid, domain: &Domain, x: &[Vec3]) {
        let ncell = grid.count();
        self.cell_start.clear();
        self.cell_start.resize(ncell + 1, 0);
        self.cell_of.clear();
        self.cell_of
            .extend(x.iter().map(|p| grid.index(grid.coords(domain, p)) as u32));
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.cell_items.clear();
        self.cell_items.resize(x.len(), 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start);
        for (a, &c) in self.cell_of.iter().enumerate() {
            self.cell_items[self.fill[c as usize] as usize] = a as u32;
            self.fill[c as usize] += 1;
        }
    }
}

/// Fills the per-particle slot lists. Iterating pairs in (P, I) order visits, for particle a,
/// first the pairs where a is I (partners < a, increasing) and then those where a is P
/// (partners > a, increasing): each list comes out sorted by partner id.
fn build_adjacency(list: &mut PairList, n: usize, fill: &mut Vec<u32>) {
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
    fill.clear();
    fill.extend_from_slice(&list.adj_start[..n]);
    for k in 0..list.p.len() {
        let (p, i) = (list.p[k] as usize, list.i[k] as usize);
        list.adj[fill[p] as usize] = (k as u32) << 1;
        fill[p] += 1;
        list.adj[fill[i] as usize] = ((k as u32) << 1) | 1;
        fill[i] += 1;
    }
}

/// Copies per-pair history from an old list to a new one, matching pairs by `(p, i)`; pairs
/// that are new get `T::default()`. Both lists are in canonical order, so one merge pass does.
pub fn carry_history<T: Copy + Default>(
    old_p: &[u32],
    old_i: &[u32],
    old_h: &[T],
    new: &PairList,
    new_h: &mut Vec<T>,
) {
    new_h.clear();
    new_h.resize(new.p.len(), T::default());
    let key = |p: u32, i: u32| ((p as u64) << 32) | i as u64;
    let mut o = 0;
    for k in 0..new.p.len() {
        let kn = key(new.p[k], new.i[k]);
        while o < old_p.len() && key(old_p[o], old_i[o]) < kn {
            o += 1;
        }
        if o < old_p.len() && key(old_p[o], old_i[o]) == kn {
            new_h[k] = old_h[o];
        }
    }
}

/// Cell grid over the box; periodic axes wrap, others clamp.
struct Grid {
    n: [usize; 3],
    edge: [f64; 3],
    periodic: [bool; 3],
}

impl Grid {
    fn new(domain: &Domain, cell: f64) -> Self {
        let l = domain.lengths();
        let mut n = [1usize; 3];
        let mut edge = [0.0; 3];
        for k in 0..3 {
            n[k] = ((l[k] / cell).floor() as usize).max(1);
            edge[k] = l[k] / n[k] as f64;
        }
        Grid {
            n,
            edge,
            periodic: domain.periodic,
        }
    }

    fn count(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    fn coords(&self, domain: &Domain, x: &Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let f = ((x[k] - domain.lo[k]) / self.edge[k]).floor();
            c[k] = (f.max(0.0) as usize).min(self.n[k] - 1);
        }
        c
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    /// The distinct cells adjacent to (and including) cell `c`.
    fn neighbours(&self, c: [usize; 3]) -> impl Iterator<Item = usize> {
        let mut out = [usize::MAX; 27];
        let mut len = 0;
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let mut cc = [0usize; 3];
                    let mut inside = true;
                    for (k, d) in [dx, dy, dz].into_iter().enumerate() {
                        let m = self.n[k] as i64;
                        let v = c[k] as i64 + d;
                        if self.periodic[k] {
                            cc[k] = v.rem_euclid(m) as usize;
                        } else if v < 0 || v >= m {
                            inside = false;
                        } else {
                            cc[k] = v as usize;
                        }
                    }
                    if inside {
                        let idx = self.index(cc);
                        if !out[..len].contains(&idx) {
                            out[len] = idx;
                            len += 1;
                        }
                    }
                }
            }
        }
        out.into_iter().take(len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_scene(n: usize, seed: u64) -> (Domain, Vec<Vec3>, Vec<f64>) {
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
        (domain, x, vec![0.5; n])
    }

    #[test]
    fn cell_search_finds_exactly_the_all_pairs_list_in_canonical_order() {
        let (domain, x, r) = random_scene(300, 7);
        let mut a = PairList::default();
        let mut b = PairList::default();
        NeighborBuilder::new(0.3, 0.0, 0.5, Search::Cells).build(&mut a, &domain, &x, &r, |_, _| true);
        NeighborBuilder::new(0.3, 0.0, 0.5, Search::AllPairs).build(&mut b, &domain, &x, &r, |_, _| true);
        assert!(!a.p.is_empty());
        assert_eq!(a.p, b.p);
        assert_eq!(a.i, b.i);
    }

    #[test]
    fn adjacency_lists_are_sorted_by_partner() {
        let (domain, x, r) = random_scene(200, 3);
        let mut l = PairList::default();
        NeighborBuilder::new(0.5, 0.0, 0.5, Search::Cells).build(&mut l, &domain, &x, &r, |_, _| true);
        for a in 0..x.len() {
            let partners: Vec<u32> = l.adj[l.adj_start[a] as usize..l.adj_start[a + 1] as usize]
                .iter()
                .map(|&e| {
                    let k = (e >> 1) as usize;
                    if e & 1 == 0 { l.i[k] } else { l.p[k] }
                })
                .collect();
            assert!(partners.windows(2).all(|w| w[0] < w[1]), "particle {a}");
        }
    }

    #[test]
    fn history_follows_its_pair_across_a_rebuild() {
        let mut new = PairList::default();
        new.p = vec![0, 0, 2];
        new.i = vec![1, 3, 5];
        let mut h = Vec::new();
        carry_history(&[0, 2, 4], &[3, 5, 6], &[1.0, 2.0, 3.0], &new, &mut h);
        assert_eq!(h, vec![0.0, 1.0, 2.0]);
    }
}
