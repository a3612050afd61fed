//! Terrain meshes in PLY files (the thesis exported its grounds from Blender as PLY, Section
//! 7.7.5), read and written with the `ply-rs-bw` crate: ASCII, binary little and big endian;
//! element `vertex` with scalar properties `x`, `y`, `z` (float or double; other properties
//! are ignored), element `face` with a list property `vertex_indices` (or `vertex_index`) of
//! any integer type. Faces of more than three vertices are cut into a fan of triangles from
//! their first vertex (exact for the convex planar polygons Blender writes); other elements are
//! ignored. Every problem is one [`PlyError`] naming the file and the element.

use std::io::Write;
use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{Addable, DefaultElement, ElementDef, Ply, Property, PropertyDef, PropertyType, ScalarType};
pub use ply_rs_bw::ply::Encoding;
use ply_rs_bw::writer::Writer;

use super::{MeshError, MeshTerrain, Triangles};

/// A PLY file that does not hold a terrain mesh.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {element}: {problem}")]
pub struct PlyError {
    pub file: String,
    /// The element at fault (`header`, `vertex 12`, `face 3`, ...), or where the parser stopped.
    pub element: String,
    pub problem: String,
}

/// How a PLY file is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlyFormat {
    pub encoding: Encoding,
    /// `float` (Blender's) or `double` vertex coordinates.
    pub double: bool,
}

/// Reads a terrain mesh from a PLY file.
pub fn read_terrain(path: &Path) -> Result<MeshTerrain, PlyError> {
    let file = path.display().to_string();
    let bytes = crate::fields::read_input_bytes(path, crate::fields::MAX_MESH_BYTES).map_err(|problem| PlyError { file: file.clone(), element: "file".into(), problem })?;
    parse_terrain(&bytes, &file)
}

/// [`read_terrain`] of the bytes of a file named `file`.
pub fn parse_terrain(bytes: &[u8], file: &str) -> Result<MeshTerrain, PlyError> {
    let (triangles, origin) = parse_faces(bytes, file)?;
    MeshTerrain::new(triangles).map_err(|e| {
        let (element, problem) = match e {
            MeshError::Empty => ("face".to_string(), "no faces; allowed: at least one triangle".to_string()),
            MeshError::NonFiniteVertex { index, position: [x, y, z] } => (format!("vertex {index}"), format!("({x}, {y}, {z}) is not finite; allowed: finite coordinates")),
            MeshError::IndexOutOfRange { face, indices, index, vertices } => {
                (format!("face {}", origin[face]), format!("{indices:?}: vertex index {index} out of range; allowed: 0..{vertices} (the file has {vertices} vertices)"))
            }
            MeshError::Degenerate { face, indices } => (format!("face {}", origin[face]), format!("{indices:?}: degenerate (zero area); allowed: a triangle of three distinct, non-collinear vertices")),
        };
        PlyError { file: file.to_string(), element, problem }
    })
}

/// The vertices and triangles of a PLY file (faces of more than three vertices cut into fans),
/// not yet checked as a terrain.
pub fn parse(bytes: &[u8], file: &str) -> Result<Triangles, PlyError> {
    parse_faces(bytes, file).map(|(t, _)| t)
}

/// [`parse`] with the file's face number of each triangle.
fn parse_faces(bytes: &[u8], file: &str) -> Result<(Triangles, Vec<usize>), PlyError> {
    let err = |element: String, problem: String| PlyError { file: file.to_string(), element, problem };
    let ply = Parser::<DefaultElement>::new().read_ply(&mut &bytes[..]).map_err(|e| {
        let element = e.line().map_or("file".to_string(), |l| format!("line {l}"));
        let message = e.to_string();
        let message = message.split_once(": ").filter(|_| e.line().is_some()).map_or(message.as_str(), |(_, m)| m);
        // The parser's messages span lines (the offending line quoted): one line here.
        err(element, message.split_whitespace().collect::<Vec<_>>().join(" "))
    })?;
    let vertex_def = ply.header.elements.get("vertex").ok_or_else(|| err("header".into(), "no `element vertex`".into()))?;
    for axis in ["x", "y", "z"] {
        match vertex_def.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            _ => return Err(err("header".into(), format!("`element vertex` has no scalar property `{axis}`; allowed: x, y, z as float or double"))),
        }
    }
    let face_def = ply.header.elements.get("face").ok_or_else(|| err("header".into(), "no `element face`".into()))?;
    let index_name = ["vertex_indices", "vertex_index"].into_iter().find(|n| matches!(face_def.properties.get(*n).map(|p| &p.data_type), Some(PropertyType::List(..))));
    let index_name = index_name.ok_or_else(|| err("header".into(), "`element face` has no list property `vertex_indices` (or `vertex_index`)".into()))?;

    let empty = Vec::new();
    let mut t = Triangles::default();
    let mut origin = Vec::new();
    for (n, v) in ply.payload.get("vertex").unwrap_or(&empty).iter().enumerate() {
        let coordinate = |axis: &str| scalar(v.get(axis)).ok_or_else(|| err(format!("vertex {n}"), format!("`{axis}` is not a number")));
        t.vertices.push([coordinate("x")?, coordinate("y")?, coordinate("z")?]);
    }
    for (n, f) in ply.payload.get("face").unwrap_or(&empty).iter().enumerate() {
        let indices = indices(f.get(index_name)).ok_or_else(|| err(format!("face {n}"), format!("`{index_name}` holds a negative or non-integer vertex index")))?;
        if indices.len() < 3 {
            return Err(err(format!("face {n}"), format!("{} vertices {indices:?}; allowed: a polygon of at least 3 vertices", indices.len())));
        }
        for k in 1..indices.len() - 1 {
            t.faces.push([indices[0], indices[k], indices[k + 1]]);
            origin.push(n);
        }
    }
    Ok((t, origin))
}

fn scalar(p: Option<&Property>) -> Option<f64> {
    Some(match p? {
        Property::Char(v) => *v as f64,
        Property::UChar(v) => *v as f64,
        Property::Short(v) => *v as f64,
        Property::UShort(v) => *v as f64,
        Property::Int(v) => *v as f64,
        Property::UInt(v) => *v as f64,
        Property::Float(v) => *v as f64,
        Property::Double(v) => *v,
        _ => return None,
    })
}

fn indices(p: Option<&Property>) -> Option<Vec<u32>> {
    fn all<T: Copy>(v: &[T], f: impl Fn(T) -> Option<u32>) -> Option<Vec<u32>> {
        v.iter().map(|&x| f(x)).collect()
    }
    match p? {
        Property::ListChar(v) => all(v, |x| u32::try_from(x).ok()),
        Property::ListUChar(v) => all(v, |x| Some(x as u32)),
        Property::ListShort(v) => all(v, |x| u32::try_from(x).ok()),
        Property::ListUShort(v) => all(v, |x| Some(x as u32)),
        Property::ListInt(v) => all(v, |x| u32::try_from(x).ok()),
        Property::ListUInt(v) => all(v, Some),
        _ => None,
    }
}

/// Writes triangles as a PLY file: `vertex` with x, y, z, `face` with a `vertex_indices` list
/// (uchar count, int indices, as Blender writes).
pub fn write(t: &Triangles, format: PlyFormat, out: &mut impl Write) -> std::io::Result<()> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = format.encoding;
    ply.header.comments.push("hexadyn terrain".to_string());
    let scalar_type = if format.double { ScalarType::Double } else { ScalarType::Float };
    let mut vertex = ElementDef::new("vertex".to_string());
    for axis in ["x", "y", "z"] {
        vertex.properties.add(PropertyDef::new(axis.to_string(), PropertyType::Scalar(scalar_type.clone())));
    }
    ply.header.elements.add(vertex);
    let mut face = ElementDef::new("face".to_string());
    face.properties.add(PropertyDef::new("vertex_indices".to_string(), PropertyType::List(ScalarType::UChar, ScalarType::Int)));
    ply.header.elements.add(face);
    let vertices = t
        .vertices
        .iter()
        .map(|v| {
            let mut e = DefaultElement::new();
            for (axis, x) in ["x", "y", "z"].into_iter().zip(v) {
                e.insert(axis.to_string(), if format.double { Property::Double(*x) } else { Property::Float(*x as f32) });
            }
            e
        })
        .collect();
    ply.payload.insert("vertex".to_string(), vertices);
    let faces = t
        .faces
        .iter()
        .map(|f| {
            let mut e = DefaultElement::new();
            e.insert("vertex_indices".to_string(), Property::ListInt(f.iter().map(|&i| i as i32).collect()));
            e
        })
        .collect();
    ply.payload.insert("face".to_string(), faces);
    Writer::new().write_ply(out, &mut ply).map(|_| ())
}

#[cfg(test)]
mod tests;
