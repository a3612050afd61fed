//! The `[terrain]` table of a scenario file: the ground the robot stands and walks on
//! (`docs/scenario-format.md`). Without the table the ground is flat at z = 0.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::Deserialize;

use crate::fields::{Ctx, DescriptionError};
use crate::physics::terrain::ply;
use crate::physics::{FlatGround, Heightfield, Slope, Step, Terrain};

/// `[terrain]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTerrain {
    kind: TerrainKind,
    height_m: Option<f64>,
    angle_deg: Option<f64>,
    azimuth_deg: Option<f64>,
    rise_m: Option<f64>,
    edge_m: Option<f64>,
    file: Option<String>,
    spacing_m: Option<f64>,
    origin_m: Option<[f64; 2]>,
}

#[derive(Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum TerrainKind {
    Flat,
    Slope,
    Step,
    Heightfield,
    Mesh,
}

/// The scenario's ground: flat at z = 0 without a `[terrain]` table.
pub(super) fn validate(raw: Option<&RawTerrain>, c: &Ctx, dir: &Path) -> Result<Arc<dyn Terrain>, DescriptionError> {
    let Some(t) = raw else { return Ok(Arc::new(FlatGround { height: 0.0 })) };
    let field = |name: &str| format!("terrain.{name}");
    let (kind, used): (&str, &[&str]) = match t.kind {
        TerrainKind::Flat => ("flat", &["height_m"]),
        TerrainKind::Slope => ("slope", &["angle_deg", "azimuth_deg", "height_m"]),
        TerrainKind::Step => ("step", &["rise_m", "edge_m", "azimuth_deg", "height_m"]),
        TerrainKind::Heightfield => ("heightfield", &["file", "spacing_m", "origin_m"]),
        TerrainKind::Mesh => ("mesh", &["file"]),
    };
    let number = |v: Option<f64>| v.map(|v| v.to_string());
    let written = [
        ("height_m", number(t.height_m)),
        ("angle_deg", number(t.angle_deg)),
        ("azimuth_deg", number(t.azimuth_deg)),
        ("rise_m", number(t.rise_m)),
        ("edge_m", number(t.edge_m)),
        ("file", t.file.as_ref().map(|f| format!("{f:?}"))),
        ("spacing_m", number(t.spacing_m)),
        ("origin_m", t.origin_m.map(|o| format!("{o:?}"))),
    ];
    if let Some((name, Some(value))) = written.into_iter().find(|(name, v)| v.is_some() && !used.contains(name)) {
        return Err(c.err(&field(name), value, &format!("not a field of kind = \"{kind}\""), format!("for kind = \"{kind}\": {}", used.join(", "))));
    }
    let required = |name: &str, v: Option<f64>| v.ok_or_else(|| c.err(&field(name), "<missing>", "missing field", format!("kind = \"{kind}\" needs {name}")));
    let height = t.height_m.unwrap_or(0.0);
    c.finite(&field("height_m"), height)?;
    let azimuth = t.azimuth_deg.unwrap_or(0.0);
    c.finite(&field("azimuth_deg"), azimuth)?;
    let path = |name: &str, what: &str| -> Result<PathBuf, DescriptionError> {
        let file = t.file.as_ref().ok_or_else(|| c.err(&field(name), "<missing>", "missing field", format!("kind = \"{kind}\" needs file, {what} relative to the scenario file")))?;
        Ok(if Path::new(file).is_absolute() { PathBuf::from(file) } else { dir.join(file) })
    };
    let file_shown = || format!("{:?}", t.file.as_deref().unwrap_or(""));
    Ok(match t.kind {
        TerrainKind::Flat => Arc::new(FlatGround { height }),
        TerrainKind::Slope => {
            let angle = required("angle_deg", t.angle_deg)?;
            c.check(angle.abs() < 60.0, &field("angle_deg"), angle, "an angle in (-60, 60) deg")?;
            Arc::new(Slope::from_angle(height, angle.to_radians(), azimuth.to_radians()))
        }
        TerrainKind::Step => {
            let rise = required("rise_m", t.rise_m)?;
            c.positive(&field("rise_m"), rise)?;
            let edge = required("edge_m", t.edge_m)?;
            c.finite(&field("edge_m"), edge)?;
            Arc::new(Step { base: height, rise, edge, azimuth: azimuth.to_radians() })
        }
        TerrainKind::Heightfield => {
            let what = "a CSV file of heights (m), one row per y, comma-separated";
            let file = path("file", what)?;
            let spacing = required("spacing_m", t.spacing_m)?;
            c.positive(&field("spacing_m"), spacing)?;
            let origin = t.origin_m.unwrap_or([0.0, 0.0]);
            for (k, v) in origin.iter().enumerate() {
                c.finite(&format!("terrain.origin_m[{k}]"), *v)?;
            }
            let heights = read_heights(&file).map_err(|problem| c.err(&field("file"), file_shown(), &problem, what))?;
            let field_of_heights = Heightfield::new(origin, spacing, heights)
                .map_err(|e| c.err(&field("file"), file_shown(), &format!("{}: {e}", file.display()), format!("{what}: at least 2 x 2 finite heights, every row as long")))?;
            Arc::new(field_of_heights)
        }
        TerrainKind::Mesh => {
            let what = "a PLY file (ASCII or binary; vertex x, y, z; face vertex_indices)";
            let file = path("file", what)?;
            let mesh = ply::read_terrain(&file).map_err(|e| c.err(&field("file"), file_shown(), &e.to_string(), what))?;
            Arc::new(mesh)
        }
    })
}

/// The file of a mesh terrain, as the scenario resolves it (relative to the scenario's folder;
/// `Path::join` keeps an absolute path as it is).
pub(super) fn mesh_file(raw: Option<&RawTerrain>, dir: &Path) -> Option<String> {
    let t = raw.filter(|t| t.kind == TerrainKind::Mesh)?;
    Some(dir.join(t.file.as_deref()?).display().to_string())
}

/// The rows of a CSV file of numbers (blank lines skipped).
fn read_heights(path: &Path) -> Result<Vec<Vec<f64>>, String> {
    let text = crate::fields::read_input(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let records = crate::fields::csv_records(&text, false).map_err(|(line, e)| format!("{}:{line}: {e}", path.display()))?;
    records
        .into_iter()
        .map(|(line, fields)| {
            fields.iter().enumerate().map(|(k, v)| v.parse::<f64>().map_err(|_| format!("{}:{line}: column {}: `{v}` is not a number", path.display(), k + 1))).collect()
        })
        .collect()
}
