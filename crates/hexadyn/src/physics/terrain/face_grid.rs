//! The search structure of a terrain mesh ([`super::MeshTerrain`]): a uniform grid over the XY
//! plane whose cells list the faces whose XY bounding boxes overlap them, in compressed rows
//! (one offset per cell, the faces of all cells in one array), with the height range of each
//! cell's faces.
//!
//! A terrain is a surface seen from above, so the faces near a foot are the faces over the
//! ground near it: the grid answers the vertical ray (the faces of one cell), the faces within
//! a distance (the cells of a square) and the closest face (rings of cells around the foot until
//! no unvisited cell can hold a closer face; a cell's faces are looked at only when the box of
//! the cell and its height range is nearer than the closest face so far, which spares a foot
//! high above the ground the faces under its neighbourhood). It takes a few bytes a face where
//! parry3d's BVH takes about 130 (issue 39: a terrain within a few times its file's data).

/// A face's bounding box: [x_min, y_min, z_min, x_max, y_max, z_max] (m).
pub type FaceBox = [f64; 6];

/// The XY footprint of a box: [x_min, y_min, x_max, y_max].
fn footprint(b: &FaceBox) -> [f64; 4] {
    [b[0], b[1], b[3], b[4]]
}

/// The most cell entries per face: a coarser grid is chosen until the faces' entries fit, so
/// that a mesh of large faces (a staircase's treads across the whole width) costs no more than
/// four entries a face.
const MAX_ENTRIES_PER_FACE: u64 = 4;

#[derive(Clone, Debug)]
pub struct FaceGrid {
    /// The XY corner of the first cell (m).
    origin: [f64; 2],
    /// The side of a cell (m).
    cell: f64,
    /// Cells along x and y.
    dims: [usize; 2],
    /// Where each cell's faces start in `faces` (one more than the cells).
    starts: Vec<u32>,
    /// The faces of every cell, cell after cell, each cell's in ascending order.
    faces: Vec<u32>,
    /// The lowest and highest point of each cell's faces (m; rounded outwards to f32; an empty
    /// cell's range is empty).
    heights: Vec<[f32; 2]>,
    /// The lowest and highest point of all faces (m).
    z_range: [f64; 2],
}

impl FaceGrid {
    /// The grid of `count` faces whose bounding boxes `face_box` gives (called twice per face
    /// and per trial cell size). Its cells are about as many as the faces, coarsened until every
    /// face overlaps four cells on average at most.
    pub fn new(count: usize, face_box: impl Fn(u32) -> FaceBox) -> Self {
        let mut bounds = [f64::INFINITY, f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for f in 0..count as u32 {
            let b = face_box(f);
            bounds = std::array::from_fn(|k| if k < 3 { bounds[k].min(b[k]) } else { bounds[k].max(b[k]) });
        }
        let (width, height) = (bounds[3] - bounds[0], bounds[4] - bounds[1]);
        let n = count.max(1) as f64;
        // Cells about as many as the faces; a mesh along a line (a wall alone) by its length.
        let mut cell = (width * height / n).sqrt().max(width.max(height) / n).max(1e-9);
        let mut grid = FaceGrid { origin: [bounds[0], bounds[1]], cell, dims: [1, 1], starts: Vec::new(), faces: Vec::new(), heights: Vec::new(), z_range: [bounds[2], bounds[5]] };
        loop {
            grid.cell = cell;
            grid.dims = [(width / cell) as usize + 1, (height / cell) as usize + 1];
            let entries: u64 = (0..count as u32).map(|f| grid.cells_of(&footprint(&face_box(f)))).map(|([i0, j0], [i1, j1])| ((i1 - i0 + 1) * (j1 - j0 + 1)) as u64).sum();
            if entries <= MAX_ENTRIES_PER_FACE * count as u64 {
                break;
            }
            cell *= 2.0;
        }
        // Counts, then offsets, then the faces in ascending order within each cell.
        let mut starts = vec![0u32; grid.dims[0] * grid.dims[1] + 1];
        for f in 0..count as u32 {
            grid.for_cells(&footprint(&face_box(f)), |c| starts[c + 1] += 1);
        }
        for c in 1..starts.len() {
            starts[c] += starts[c - 1];
        }
        let mut next = starts.clone();
        let mut faces = vec![0u32; starts[starts.len() - 1] as usize];
        let mut heights = vec![[f32::INFINITY, f32::NEG_INFINITY]; grid.dims[0] * grid.dims[1]];
        for f in 0..count as u32 {
            let b = face_box(f);
            // Rounded outwards: the range holds the faces' heights exactly.
            let (low, high) = (b[2] as f32, b[5] as f32);
            let low = if f64::from(low) > b[2] { low.next_down() } else { low };
            let high = if f64::from(high) < b[5] { high.next_up() } else { high };
            grid.for_cells(&footprint(&b), |c| {
                faces[next[c] as usize] = f;
                next[c] += 1;
                heights[c] = [heights[c][0].min(low), heights[c][1].max(high)];
            });
        }
        grid.starts = starts;
        grid.faces = faces;
        grid.heights = heights;
        grid
    }

    /// The bytes the grid holds.
    pub fn bytes(&self) -> usize {
        4 * (self.starts.len() + self.faces.len()) + 8 * self.heights.len()
    }

    /// The cell index along x (`axis` 0) or y (1) of a coordinate, clamped to the grid.
    fn index(&self, axis: usize, x: f64) -> usize {
        (((x - self.origin[axis]) / self.cell).floor().max(0.0) as usize).min(self.dims[axis] - 1)
    }

    /// The first and last cells (i, j) an XY footprint [x_min, y_min, x_max, y_max] overlaps.
    fn cells_of(&self, b: &[f64; 4]) -> ([usize; 2], [usize; 2]) {
        ([self.index(0, b[0]), self.index(1, b[1])], [self.index(0, b[2]), self.index(1, b[3])])
    }

    /// Calls `visit` with the number of every cell a footprint overlaps.
    fn for_cells(&self, b: &[f64; 4], mut visit: impl FnMut(usize)) {
        let ([i0, j0], [i1, j1]) = self.cells_of(b);
        for j in j0..=j1 {
            for i in i0..=i1 {
                visit(j * self.dims[0] + i);
            }
        }
    }

    fn cell_faces(&self, c: usize) -> &[u32] {
        &self.faces[self.starts[c] as usize..self.starts[c + 1] as usize]
    }

    /// The distance from `p` to cell `c`'s box: its square in XY, its faces' height range in z
    /// (infinite for an empty cell). The faces of the cell whose closest point to `p` lies over
    /// the cell are at least that far.
    fn cell_distance(&self, c: usize, p: [f64; 3]) -> f64 {
        let [low, high] = self.heights[c].map(f64::from);
        if low > high {
            return f64::INFINITY;
        }
        let (i, j) = (c % self.dims[0], c / self.dims[0]);
        let x0 = self.origin[0] + i as f64 * self.cell;
        let y0 = self.origin[1] + j as f64 * self.cell;
        let dx = (x0 - p[0]).max(p[0] - (x0 + self.cell)).max(0.0);
        let dy = (y0 - p[1]).max(p[1] - (y0 + self.cell)).max(0.0);
        let dz = (low - p[2]).max(p[2] - high).max(0.0);
        (dx * dx + dy * dy + dz * dz).sqrt()
    }

    /// The faces whose footprint may hold (x, y): those of its cell; none off the grid.
    pub fn at(&self, x: f64, y: f64) -> &[u32] {
        let inside = |axis: usize, v: f64| v >= self.origin[axis] && v <= self.origin[axis] + self.dims[axis] as f64 * self.cell;
        if inside(0, x) && inside(1, y) {
            self.cell_faces(self.index(1, y) * self.dims[0] + self.index(0, x))
        } else {
            &[]
        }
    }

    /// Calls `visit` with the faces of the cells within `reach` of `p` (a face once per cell it
    /// overlaps): every face with a point within `reach` of `p` is among them (the cell under
    /// that point holds it and is within `reach`).
    pub fn near(&self, p: [f64; 3], reach: f64, mut visit: impl FnMut(u32)) {
        self.for_cells(&[p[0] - reach, p[1] - reach, p[0] + reach, p[1] + reach], |c| {
            // A nanometre of slack for the rounding of the cells' edges.
            if self.cell_distance(c, p) <= reach + 1e-9 {
                self.cell_faces(c).iter().for_each(|&f| visit(f));
            }
        });
    }

    /// Visits the cells in square rings around the cell under `p` (the nearest cell when `p`
    /// is off the grid), calling `visit` with the faces of each cell nearer to `p` than the
    /// closest face so far, which `visit` returns. Stops once every unvisited cell is as far in
    /// XY (and in z from the faces' height range) as that or farther: the face closest to `p` is
    /// in the cell under its closest point, which is at least as near as that point, and a cell
    /// no nearer than the closest face so far holds no closer face (ties are not looked into:
    /// far from the ground, where every cell's distance rounds to the same, the search stays
    /// under the point instead of visiting the whole grid).
    pub fn rings(&self, p: [f64; 3], mut visit: impl FnMut(&[u32]) -> f64) {
        let [nx, ny] = self.dims.map(|d| d as isize);
        let (i0, j0) = (self.index(0, p[0]) as isize, self.index(1, p[1]) as isize);
        let edge = |axis: usize, k: isize| self.origin[axis] + k as f64 * self.cell;
        let dz = (self.z_range[0] - p[2]).max(p[2] - self.z_range[1]).max(0.0);
        let distance_to = |x0: f64, x1: f64, y0: f64, y1: f64| {
            let dx = (x0 - p[0]).max(p[0] - x1).max(0.0);
            let dy = (y0 - p[1]).max(p[1] - y1).max(0.0);
            (dx * dx + dy * dy + dz * dz).sqrt()
        };
        let mut best = f64::INFINITY;
        for r in 0.. {
            for j in (j0 - r).max(0)..=(j0 + r).min(ny - 1) {
                // The ring's bottom and top rows whole, its left and right cells in between.
                let (mut i, step) = if (j - j0).abs() == r { ((i0 - r).max(0), 1) } else { (i0 - r, 2 * r) };
                while i <= (i0 + r).min(nx - 1) {
                    let c = (j * nx + i) as usize;
                    // A nanometre of slack for the rounding of the cells' edges.
                    if i >= 0 && self.cell_distance(c, p) < best + 1e-9 {
                        best = visit(self.cell_faces(c));
                    }
                    i += step;
                }
            }
            // The unvisited cells: the strips beyond the visited square on each side.
            let (left, right, bottom, top) = (i0 - r, i0 + r, j0 - r, j0 + r);
            let (x_min, x_max, y_min, y_max) = (edge(0, 0), edge(0, nx), edge(1, 0), edge(1, ny));
            let mut nearest_unvisited = f64::INFINITY;
            if left > 0 {
                nearest_unvisited = nearest_unvisited.min(distance_to(x_min, edge(0, left), y_min, y_max));
            }
            if right < nx - 1 {
                nearest_unvisited = nearest_unvisited.min(distance_to(edge(0, right + 1), x_max, y_min, y_max));
            }
            if bottom > 0 {
                nearest_unvisited = nearest_unvisited.min(distance_to(x_min, x_max, y_min, edge(1, bottom)));
            }
            if top < ny - 1 {
                nearest_unvisited = nearest_unvisited.min(distance_to(x_min, x_max, edge(1, top + 1), y_max));
            }
            // A NaN distance visits every cell.
            if nearest_unvisited == f64::INFINITY || best + 1e-9 <= nearest_unvisited {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random boxes of sizes 0 to `size` (z: 0 to 0.1 m) over 10 m x 6 m, 0.2 m of heights.
    fn boxes(n: usize, size: f64, seed: u64) -> Vec<FaceBox> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let (x, y, z) = (rng.random_range(-5.0..5.0), rng.random_range(-3.0..3.0), rng.random_range(-0.1..0.1));
                [x, y, z, x + rng.random_range(0.0..size), y + rng.random_range(0.0..size), z + rng.random_range(0.0..0.1)]
            })
            .collect()
    }

    /// The distance from `p` to a box.
    fn distance(b: &FaceBox, p: [f64; 3]) -> f64 {
        (0..3).map(|k| (b[k] - p[k]).max(p[k] - b[k + 3]).max(0.0).powi(2)).sum::<f64>().sqrt()
    }

    /// The rings find the box nearest to points on and off the grid, above and among the boxes,
    /// as a scan of every box does, for small boxes and for boxes as large as the grid.
    #[test]
    fn rings_find_the_nearest_box() {
        for (size, seed) in [(0.05, 1), (0.5, 2), (12.0, 3)] {
            let boxes = boxes(2000, size, seed);
            let grid = FaceGrid::new(boxes.len(), |f| boxes[f as usize]);
            assert!(grid.faces.len() <= 4 * boxes.len(), "{} entries", grid.faces.len());
            let mut rng = ChaCha8Rng::seed_from_u64(seed + 10);
            let mut visited = 0;
            for _ in 0..500 {
                let p = [rng.random_range(-9.0..9.0), rng.random_range(-7.0..7.0), rng.random_range(-0.5..0.5)];
                let mut best = f64::INFINITY;
                grid.rings(p, |faces| {
                    visited += faces.len();
                    faces.iter().for_each(|&f| best = best.min(distance(&boxes[f as usize], p)));
                    best
                });
                let scan = boxes.iter().map(|b| distance(b, p)).fold(f64::INFINITY, f64::min);
                assert_eq!(best, scan, "size {size} at {p:?}");
            }
            if size < 0.1 {
                assert!(visited < 500 * 2000 / 10, "{visited} boxes visited in 500 searches of 2000");
            }
        }
    }

    /// A point so far from the grid that every cell is at the same distance in floating point (a
    /// trial state of a Newton iteration gone astray, a foot 1e10 m below the ground) looks
    /// at the cells under it, not at every cell: the faces of a cell no nearer than the closest
    /// so far cannot be closer.
    #[test]
    fn rings_stop_at_ties_far_away() {
        let boxes = boxes(2000, 0.05, 6);
        let grid = FaceGrid::new(boxes.len(), |f| boxes[f as usize]);
        for p in [[0.0, 0.0, -1e10], [1.0, -2.0, 3e9], [4e12, 0.0, 0.0]] {
            let (mut visited, mut best) = (0, f64::INFINITY);
            grid.rings(p, |faces| {
                visited += faces.len();
                best = faces.iter().map(|&f| distance(&boxes[f as usize], p)).fold(best, f64::min);
                best
            });
            assert!((1..100).contains(&visited), "{visited} boxes of 2000 visited from {p:?}");
        }
    }

    /// `near` visits every box within the reach; `at` every box over the point.
    #[test]
    fn near_and_at_miss_no_box() {
        let boxes = boxes(3000, 0.2, 4);
        let grid = FaceGrid::new(boxes.len(), |f| boxes[f as usize]);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..300 {
            let p = [rng.random_range(-6.0..6.0), rng.random_range(-4.0..4.0), rng.random_range(-0.3..0.3)];
            let reach = rng.random_range(0.0..0.5);
            let mut seen = vec![false; boxes.len()];
            grid.near(p, reach, |f| seen[f as usize] = true);
            let at = grid.at(p[0], p[1]);
            for (f, b) in boxes.iter().enumerate() {
                if distance(b, p) <= reach {
                    assert!(seen[f], "box {f} within {reach} of {p:?} not visited");
                }
                if distance(b, [p[0], p[1], b[2]]) == 0.0 {
                    assert!(at.contains(&(f as u32)), "box {f} is over {p:?} but not in its cell");
                }
            }
        }
    }
}
