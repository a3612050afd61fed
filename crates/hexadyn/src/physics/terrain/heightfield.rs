//! A terrain of heights on a regular grid.

use nalgebra::Vector3;

use super::{Extent, MeshError, MeshTerrain, Proximity, Terrain, Triangles, Vicinity};

/// Heights z_ij at (x_0 + i Δ, y_0 + j Δ), i = 0..n_x, j = 0..n_y, each cell cut into two
/// triangles along its diagonal from (i, j) to (i + 1, j + 1): the surface is continuous and
/// piecewise planar. The height under a point comes from its cell's triangle directly; the
/// closest-point contact from the mesh of those triangles ([`MeshTerrain`]). Outside the grid
/// the height is that of the nearest border cell's plane.
#[derive(Clone, Debug)]
pub struct Heightfield {
    origin: [f64; 2],
    spacing: f64,
    /// `heights[j][i]`, rows along y.
    heights: Vec<Vec<f64>>,
    mesh: MeshTerrain,
}

/// Why a grid does not make a heightfield.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HeightfieldError {
    #[error("{rows} rows: at least 2 needed")]
    TooFewRows { rows: usize },
    #[error("row {row} has {columns} heights: at least 2 needed, and as many as row 0 ({first})")]
    Ragged { row: usize, columns: usize, first: usize },
    #[error("row {row}, column {column}: height {value} is not finite")]
    NonFinite { row: usize, column: usize, value: f64 },
    #[error("spacing {0}: not a finite number > 0")]
    Spacing(f64),
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

impl Heightfield {
    pub fn new(origin: [f64; 2], spacing: f64, heights: Vec<Vec<f64>>) -> Result<Self, HeightfieldError> {
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(HeightfieldError::Spacing(spacing));
        }
        if heights.len() < 2 {
            return Err(HeightfieldError::TooFewRows { rows: heights.len() });
        }
        let first = heights[0].len();
        for (row, r) in heights.iter().enumerate() {
            if r.len() < 2 || r.len() != first {
                return Err(HeightfieldError::Ragged { row, columns: r.len(), first });
            }
            if let Some((column, &value)) = r.iter().enumerate().find(|(_, z)| !z.is_finite()) {
                return Err(HeightfieldError::NonFinite { row, column, value });
            }
        }
        let t = grid_triangles(origin, spacing, &heights);
        let mesh = MeshTerrain::new(t)?;
        Ok(Heightfield { origin, spacing, heights, mesh })
    }
}

/// The two triangles of each cell of a grid of heights `heights[j][i]` at
/// (x_0 + i Δ, y_0 + j Δ), cut along the diagonal from (i, j) to (i + 1, j + 1).
pub(crate) fn grid_triangles(origin: [f64; 2], spacing: f64, heights: &[Vec<f64>]) -> Triangles {
    let (nx, ny) = (heights[0].len(), heights.len());
    let mut t = Triangles::default();
    for (j, row) in heights.iter().enumerate() {
        for (i, &z) in row.iter().enumerate() {
            t.vertices.push([origin[0] + i as f64 * spacing, origin[1] + j as f64 * spacing, z]);
        }
    }
    let index = |i: usize, j: usize| (j * nx + i) as u32;
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            t.faces.push([index(i, j), index(i + 1, j), index(i + 1, j + 1)]);
            t.faces.push([index(i, j), index(i + 1, j + 1), index(i, j + 1)]);
        }
    }
    t
}

impl Terrain for Heightfield {
    /// The plane of the cell's triangle under (x, y).
    fn height_normal(&self, x: f64, y: f64) -> (f64, Vector3<f64>) {
        let (nx, ny) = (self.heights[0].len(), self.heights.len());
        let cell = |v: f64, origin: f64, n: usize| {
            let u = (v - origin) / self.spacing;
            let k = (u.floor().max(0.0) as usize).min(n - 2);
            (k, u - k as f64)
        };
        let ((i, fx), (j, fy)) = (cell(x, self.origin[0], nx), cell(y, self.origin[1], ny));
        let z = |i: usize, j: usize| self.heights[j][i];
        // Slopes ∂h/∂x, ∂h/∂y of the triangle: below the diagonal (fx >= fy) the one through
        // (i, j), (i + 1, j), (i + 1, j + 1), above it the one through (i, j), (i + 1, j + 1), (i, j + 1).
        let (sx, sy) = if fx >= fy { (z(i + 1, j) - z(i, j), z(i + 1, j + 1) - z(i + 1, j)) } else { (z(i + 1, j + 1) - z(i, j + 1), z(i, j + 1) - z(i, j)) };
        let h = z(i, j) + sx * fx + sy * fy;
        (h, Vector3::new(-sx / self.spacing, -sy / self.spacing, 1.0).normalize())
    }

    fn proximity(&self, p: &Vector3<f64>, radius: f64) -> Proximity {
        self.mesh.proximity(p, radius)
    }

    fn proximity_near(&self, p: &Vector3<f64>, radius: f64, vicinity: &mut Vicinity) -> Proximity {
        self.mesh.proximity_near(p, radius, vicinity)
    }

    fn triangles(&self, extent: Extent) -> Triangles {
        self.mesh.triangles(extent)
    }
}
