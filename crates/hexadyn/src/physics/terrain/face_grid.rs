//! The search structure of a terrain mesh ([`super::MeshTerrain`]): a uniform grid over the XY
//! plane whose cells list the faces whose XY bounding boxes overlap them, in compressed rows
//! (one offset per cell, the faces of all cells in one array).
//!
//! A terrain is a surface seen from above, so the faces near a foot are the faces over the
//! ground near it: the grid answers the vertical ray (the faces of one cell), the faces within
//! a distance (the cells of a square) and the closest face (rings of cells around the foot until
//! no unvisited cell can hold a closer face). It takes a few bytes a face where parry3d's BVH
//! takes about 130 (issue 39: a terrain within a few times its file's data).

/// A face's bounding box in the XY plane: [x_min, y_min, x_max, y_max] (m).
pub type FootPrint = [f64; 4];

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
}

impl FaceGrid {
    /// The grid of `count` faces whose footprints `footprint` gives (called twice per face
    /// and per trial cell size). Its cells are about as many as the faces, coarsened until every
    /// face overlaps four cells on average at most.
    pub fn new(count: usize, footprint: impl Fn(u32) -> FootPrint) -> Self {
        let mut bounds = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for f in 0..count as u32 {
            let b = footprint(f);
            bounds = [bounds[0].min(b[0]), bounds[1].min(b[1]), bounds[2].max(b[2]), bounds[3].max(b[3])];
        }
        let (width, height) = (bounds[2] - bounds[0], bounds[3] - bounds[1]);
        let n = count.max(1) as f64;
        // Cells about as many as the faces; a mesh along a line (a wall alone) by its length.
        let mut cell = (width * height / n).sqrt().max(width.max(height) / n).max(1e-9);
        let mut grid = FaceGrid { origin: [bounds[0], bounds[1]], cell, dims: [1, 1], starts: Vec::new(), faces: Vec::new() };
        loop {
            grid.cell = cell;
            grid.dims = [(width / cell) as usize + 1, (height / cell) as usize + 1];
            let entries: u64 = (0..count as u32).map(|f| grid.cells_of(&footprint(f))).map(|([i0, j0], [i1, j1])| ((i1 - i0 + 1) * (j1 - j0 + 1)) as u64).sum();
            if entries <= MAX_ENTRIES_PER_FACE * count as u64 {
                break;
            }
            cell *= 2.0;
        }
        // Counts, then offsets, then the faces in ascending order within each cell.
        let mut starts = vec![0u32; grid.dims[0] * grid.dims[1] + 1];
        for f in 0..count as u32 {
            grid.for_cells(&footprint(f), |c| starts[c + 1] += 1);
        }
        for c in 1..starts.len() {
            starts[c] += starts[c - 1];
        }
        let mut next = starts.clone();
        let mut faces = vec![0u32; starts[starts.len() - 1] as usize];
        for f in 0..count as u32 {
            grid.for_cells(&footprint(f), |c| {
                faces[next[c] as usize] = f;
                next[c] += 1;
            });
        }
        grid.starts = starts;
        grid.faces = faces;
        grid
    }

    /// The bytes the grid holds.
    pub fn bytes(&self) -> usize {
        4 * (self.starts.len() + self.faces.len())
    }

    /// The cell index along x (`axis` 0) or y (1) of a coordinate, clamped to the grid.
    fn index(&self, axis: usize, x: f64) -> usize {
        (((x - self.origin[axis]) / self.cell).floor().max(0.0) as usize).min(self.dims[axis] - 1)
    }

    /// The first and last cells (i, j) a footprint overlaps.
    fn cells_of(&self, b: &FootPrint) -> ([usize; 2], [usize; 2]) {
        ([self.index(0, b[0]), self.index(1, b[1])], [self.index(0, b[2]), self.index(1, b[3])])
    }

    /// Calls `visit` with the number of every cell a footprint overlaps.
    fn for_cells(&self, b: &FootPrint, mut visit: impl FnMut(usize)) {
        let ([i0, j0], [i1, j1]) = self.cells_of(b);
        for j in j0..=j1 {
            for i in i0..=i1 {
                visit(j * self.dims[0] + i);
            }
        }
    }

    fn cell_faces(&self, i: usize, j: usize) -> &[u32] {
        let c = j * self.dims[0] + i;
        &self.faces[self.starts[c] as usize..self.starts[c + 1] as usize]
    }

    /// The faces whose footprint may hold (x, y): those of its cell; none off the grid.
    pub fn at(&self, x: f64, y: f64) -> &[u32] {
        let inside = |axis: usize, v: f64| v >= self.origin[axis] && v <= self.origin[axis] + self.dims[axis] as f64 * self.cell;
        if inside(0, x) && inside(1, y) {
            self.cell_faces(self.index(0, x), self.index(1, y))
        } else {
            &[]
        }
    }

    /// Calls `visit` with the faces of the cells the square of half side `reach` around
    /// (x, y) overlaps (a face once per cell it overlaps): every face whose footprint comes
    /// within `reach` of (x, y) is among them.
    pub fn near(&self, x: f64, y: f64, reach: f64, mut visit: impl FnMut(u32)) {
        self.for_cells(&[x - reach, y - reach, x + reach, y + reach], |c| {
            self.faces[self.starts[c] as usize..self.starts[c + 1] as usize].iter().for_each(|&f| visit(f));
        });
    }

    /// Visits the cells in square rings around the cell of (x, y) (the nearest cell when (x, y)
    /// is off the grid), calling `visit` with each cell's faces; `visit` returns the distance
    /// of the closest face found so far. Stops once every unvisited cell is farther in XY than
    /// that distance: a face none of whose cells was visited lies within unvisited cells, and a
    /// point's distance to a face is at least its XY distance to the face's footprint.
    pub fn rings(&self, x: f64, y: f64, mut visit: impl FnMut(&[u32]) -> f64) {
        let [nx, ny] = self.dims.map(|d| d as isize);
        let (i0, j0) = (self.index(0, x) as isize, self.index(1, y) as isize);
        let edge = |axis: usize, k: isize| self.origin[axis] + k as f64 * self.cell;
        let distance_to = |x0: f64, x1: f64, y0: f64, y1: f64| {
            let dx = (x0 - x).max(x - x1).max(0.0);
            let dy = (y0 - y).max(y - y1).max(0.0);
            dx.hypot(dy)
        };
        let mut best = f64::INFINITY;
        for r in 0.. {
            for j in (j0 - r).max(0)..=(j0 + r).min(ny - 1) {
                // The ring's bottom and top rows whole, its left and right cells in between.
                let (mut i, step) = if (j - j0).abs() == r { ((i0 - r).max(0), 1) } else { (i0 - r, 2 * r) };
                while i <= (i0 + r).min(nx - 1) {
                    if i >= 0 {
                        best = visit(self.cell_faces(i as usize, j as usize));
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
            // A nanometre of slack for the rounding of the cells' edges; a NaN distance visits
            // every cell.
            if nearest_unvisited == f64::INFINITY || best + 1e-9 < nearest_unvisited {
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

    /// Random footprints of sizes 0 to `size` over 10 m x 6 m.
    fn footprints(n: usize, size: f64, seed: u64) -> Vec<FootPrint> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let (x, y) = (rng.random_range(-5.0..5.0), rng.random_range(-3.0..3.0));
                [x, y, x + rng.random_range(0.0..size), y + rng.random_range(0.0..size)]
            })
            .collect()
    }

    /// The XY distance from (x, y) to a footprint.
    fn distance(b: &FootPrint, x: f64, y: f64) -> f64 {
        (b[0] - x).max(x - b[2]).max(0.0).hypot((b[1] - y).max(y - b[3]).max(0.0))
    }

    /// The rings find the footprint nearest to points on and off the grid, as a scan of every
    /// footprint does, for small faces and for faces as large as the grid.
    #[test]
    fn rings_find_the_nearest_footprint() {
        for (size, seed) in [(0.05, 1), (0.5, 2), (12.0, 3)] {
            let boxes = footprints(2000, size, seed);
            let grid = FaceGrid::new(boxes.len(), |f| boxes[f as usize]);
            assert!(grid.faces.len() <= 4 * boxes.len(), "{} entries", grid.faces.len());
            let mut rng = ChaCha8Rng::seed_from_u64(seed + 10);
            for _ in 0..500 {
                let (x, y) = (rng.random_range(-9.0..9.0), rng.random_range(-7.0..7.0));
                let mut best = f64::INFINITY;
                grid.rings(x, y, |faces| {
                    faces.iter().for_each(|&f| best = best.min(distance(&boxes[f as usize], x, y)));
                    best
                });
                let scan = boxes.iter().map(|b| distance(b, x, y)).fold(f64::INFINITY, f64::min);
                assert_eq!(best, scan, "size {size} at ({x}, {y})");
            }
        }
    }

    /// `near` visits every footprint within the reach; `at` every footprint holding the point.
    #[test]
    fn near_and_at_miss_no_footprint() {
        let boxes = footprints(3000, 0.2, 4);
        let grid = FaceGrid::new(boxes.len(), |f| boxes[f as usize]);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..300 {
            let (x, y, reach) = (rng.random_range(-6.0..6.0), rng.random_range(-4.0..4.0), rng.random_range(0.0..0.5));
            let mut seen = vec![false; boxes.len()];
            grid.near(x, y, reach, |f| seen[f as usize] = true);
            let at = grid.at(x, y);
            for (f, b) in boxes.iter().enumerate() {
                if distance(b, x, y) <= reach {
                    assert!(seen[f], "face {f} within {reach} of ({x}, {y}) not visited");
                }
                if distance(b, x, y) == 0.0 {
                    assert!(at.contains(&(f as u32)), "face {f} holds ({x}, {y}) but is not in its cell");
                }
            }
        }
    }
}
