//! Terrain meshes in PLY files (the thesis exported its grounds from Blender as PLY, Section
//! 7.7.5), read and written with the `ply-rs-bw` crate: ASCII, binary little and big endian;
//! element `vertex` with scalar properties `x`, `y`, `z` (float or double; other properties
//! are ignored), element `face` with a list property `vertex_indices` (or `vertex_index`) of
//! any integer type. Faces of more than three vertices are cut into a fan of triangles from
//! their first vertex (exact for the convex planar polygons Blender writes); other elements are
//! ignored. Every problem is one [`PlyError`] naming the file and the element.
//!
//! Memory: the file is read element by element (never whole) into the vertices and triangles
//! alone (24 bytes a vertex, 16 a triangle with the number of its face); the counts the header
//! declares are checked against the file's size and against [`MAX_MESH_VERTICES`] and
//! [`MAX_MESH_TRIANGLES`] before anything is read, so that a file declaring more than it holds
//! or than the bounds is refused at once. The terrain then keeps its merged vertices, faces,
//! the faces around each vertex and a grid of the faces over the ground ([`MeshTerrain`]):
//! 56 bytes a triangle at the peak of the load, 51 kept, on a binary PLY of 2 million
//! triangles (2 triangles a vertex, 19 bytes a triangle of vertex and face data in the file:
//! 2.9 times the file's data; `benches/src/bin/terrain.rs`, 2026-11-29, 2-core AMD EPYC
//! container), so at most about 230 MB at the bounds; a file of vertices without faces takes
//! 48 bytes a vertex.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Addable, DefaultElement, ElementDef, Header, Ply, Property, PropertyAccess, PropertyAccessResult, PropertyDef, PropertyType, ScalarType};
pub use ply_rs_bw::ply::Encoding;
use ply_rs_bw::writer::Writer;

use super::{MeshError, MeshTerrain, Triangles};

/// The most vertices a terrain mesh may have.
pub const MAX_MESH_VERTICES: usize = 4_000_000;
/// The most triangles a terrain mesh may have (a face of n vertices counts n - 2): 4 million, a
/// grid of 2000 x 1000 vertices, 1 cm cells over 20 m x 10 m, far above a terrain the feet
/// feel (the shipped rough ground has 38 400).
pub const MAX_MESH_TRIANGLES: usize = 4_000_000;
/// The longest header, and the longest line of an ASCII payload, read.
const MAX_LINE_BYTES: u64 = 64 << 10;

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

/// Reads a terrain mesh from a PLY file (a regular file of at most
/// [`crate::fields::MAX_MESH_BYTES`], [`crate::fields::open_input`]), streaming.
pub fn read_terrain(path: &Path) -> Result<MeshTerrain, PlyError> {
    let file = path.display().to_string();
    let (source, size) = crate::fields::open_input(path, crate::fields::MAX_MESH_BYTES).map_err(|problem| PlyError { file: file.clone(), element: "file".into(), problem })?;
    terrain(read_faces(BufReader::new(source), size, &file)?, &file)
}

/// [`read_terrain`] of the bytes of a file named `file`.
pub fn parse_terrain(bytes: &[u8], file: &str) -> Result<MeshTerrain, PlyError> {
    terrain(read_faces(bytes, bytes.len() as u64, file)?, file)
}

/// The vertices and triangles of a PLY file (faces of more than three vertices cut into fans),
/// not yet checked as a terrain.
pub fn parse(bytes: &[u8], file: &str) -> Result<Triangles, PlyError> {
    read_faces(bytes, bytes.len() as u64, file).map(|f| f.triangles)
}

/// The triangles of a file and, for each, the number of the file's face it was cut from.
struct Faces {
    triangles: Triangles,
    origin: Vec<u32>,
}

/// Checks the triangles as a terrain ([`MeshTerrain::new`]), its errors naming the file's element.
fn terrain(faces: Faces, file: &str) -> Result<MeshTerrain, PlyError> {
    let Faces { triangles, origin } = faces;
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

/// A parser's message on one line (it quotes the offending line on the next ones).
fn one_line(e: &ply_rs_bw::parser::ParseError) -> String {
    let message = e.to_string();
    let message = message.split_once(": ").filter(|_| e.line().is_some()).map_or(message.as_str(), |(_, m)| m);
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Reads the vertices and faces of a PLY file of `size` bytes from `source`, element by element.
fn read_faces<R: BufRead>(source: R, size: u64, file: &str) -> Result<Faces, PlyError> {
    let err = |element: String, problem: String| PlyError { file: file.to_string(), element, problem };
    let mut reader = Reader::new(source.take(MAX_LINE_BYTES));
    let header = Parser::<Skip>::new().read_header(&mut reader).map_err(|e| {
        if reader.get_ref().limit() == 0 {
            return err("header".into(), format!("no `end_header` in the first {MAX_LINE_BYTES} bytes; allowed: a PLY header of at most {MAX_LINE_BYTES} bytes"));
        }
        err(e.line().map_or("file".to_string(), |l| format!("line {l}")), one_line(&e))
    })?;
    reader.get_mut().set_limit(u64::MAX);
    let header_lines = reader.line().saturating_sub(1); // the parser's count is of the next line
    let vertex_def = header.elements.get("vertex").ok_or_else(|| err("header".into(), "no `element vertex`".into()))?;
    for axis in ["x", "y", "z"] {
        match vertex_def.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            _ => return Err(err("header".into(), format!("`element vertex` has no scalar property `{axis}`; allowed: x, y, z as float or double"))),
        }
    }
    let face_def = header.elements.get("face").ok_or_else(|| err("header".into(), "no `element face`".into()))?;
    let index = INDEX_NAMES.into_iter().position(|n| matches!(face_def.properties.get(n).map(|p| &p.data_type), Some(PropertyType::List(..))));
    let index = index.ok_or_else(|| err("header".into(), "`element face` has no list property `vertex_indices` (or `vertex_index`)".into()))?;
    check_counts(&header, size).map_err(|problem| err("header".into(), problem))?;

    let mut t = Triangles::default();
    let mut origin = Vec::new();
    let reserved = t.vertices.try_reserve_exact(vertex_def.count).and_then(|_| t.faces.try_reserve_exact(face_def.count)).and_then(|_| origin.try_reserve_exact(face_def.count));
    reserved.map_err(|e| err("file".into(), format!("{} vertices and {} faces: {e}; allowed: a mesh that fits in memory", vertex_def.count, face_def.count)))?;
    let mut lines = Lines { reader: reader.get_mut(), encoding: header.encoding, line: header_lines };
    for def in header.elements.values() {
        match def.name.as_str() {
            "vertex" => lines.each::<Vertex>(def, file, |_, v| {
                t.vertices.push(v.0);
                Ok(())
            })?,
            "face" => lines.each::<Face>(def, file, |n, f| {
                let indices = f.lists[index].as_ref().and_then(indices).ok_or_else(|| err(format!("face {n}"), format!("`{}` holds a negative or non-integer vertex index", INDEX_NAMES[index])))?;
                if indices.len() < 3 {
                    return Err(err(format!("face {n}"), format!("{} vertices {indices:?}; allowed: a polygon of at least 3 vertices", indices.len())));
                }
                if t.faces.len() + indices.len() - 2 > MAX_MESH_TRIANGLES {
                    return Err(err(format!("face {n}"), format!("more than {MAX_MESH_TRIANGLES} triangles (a face of k vertices makes k - 2); allowed: at most {MAX_MESH_TRIANGLES}")));
                }
                for k in 1..indices.len() - 1 {
                    t.faces.push([indices[0], indices[k], indices[k + 1]]);
                    origin.push(n as u32);
                }
                Ok(())
            })?,
            _ => lines.each::<Skip>(def, file, |_, _| Ok(()))?,
        }
    }
    Ok(Faces { triangles: t, origin })
}

/// Refuses counts the file cannot hold (each element takes at least its scalars' bytes and
/// its lists' counts in binary, two bytes a property in ASCII) or beyond the bounds of a
/// terrain, before anything is read.
fn check_counts(header: &Header, size: u64) -> Result<(), String> {
    let mut needed = 0u128;
    for def in header.elements.values() {
        let least: u64 = def
            .properties
            .values()
            .map(|p| match (&header.encoding, &p.data_type) {
                (Encoding::Ascii, _) => 2,
                (_, PropertyType::Scalar(s) | PropertyType::List(s, _)) => scalar_bytes(s),
            })
            .sum();
        needed += def.count as u128 * u128::from(least);
        if needed > u128::from(size) {
            return Err(format!("`element {} {}` of at least {least} bytes each: the elements up to it need at least {needed} bytes, more than the file's {size}; allowed: the counts of the elements the file holds", def.name, def.count));
        }
    }
    for (name, bound) in [("vertex", MAX_MESH_VERTICES), ("face", MAX_MESH_TRIANGLES)] {
        let count = header.elements.get(name).map_or(0, |d| d.count);
        if count > bound {
            return Err(format!("`element {name} {count}`: too many; allowed: at most {bound} (hexadyn's bound on a terrain mesh, MAX_MESH_{})", if name == "vertex" { "VERTICES" } else { "TRIANGLES" }));
        }
    }
    Ok(())
}

fn scalar_bytes(s: &ScalarType) -> u64 {
    match s {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The payload of a PLY file, read one element at a time.
struct Lines<'a, R> {
    reader: &'a mut R,
    encoding: Encoding,
    /// The last line read (ASCII).
    line: usize,
}

impl<R: BufRead> Lines<'_, R> {
    /// Reads the elements of `def`, handing each to `f` with its number.
    fn each<E: PropertyAccess>(&mut self, def: &ElementDef, file: &str, mut f: impl FnMut(usize, E) -> Result<(), PlyError>) -> Result<(), PlyError> {
        if self.encoding != Encoding::Ascii && def.properties.is_empty() {
            return Ok(()); // no bytes in a binary payload
        }
        let parser = Parser::<E>::new();
        let mut text = String::new();
        for n in 0..def.count {
            let err = |problem: String| PlyError { file: file.to_string(), element: format!("{} {n}", def.name), problem };
            let element = match self.encoding {
                Encoding::Ascii => {
                    text.clear();
                    self.line += 1;
                    let read = self.reader.by_ref().take(MAX_LINE_BYTES).read_line(&mut text).map_err(|e| err(format!("line {}: {e}", self.line)))?;
                    if read == 0 {
                        return Err(err(format!("line {}: unexpected end of file; the header declares {} {} elements", self.line, def.count, def.name)));
                    }
                    if read as u64 == MAX_LINE_BYTES && !text.ends_with('\n') {
                        return Err(err(format!("line {}: longer than {MAX_LINE_BYTES} bytes; allowed: a line of numbers", self.line)));
                    }
                    parser.read_ascii_element(&text, def).map_err(|e| err(format!("line {}: {}", self.line, one_line(&e))))?
                }
                Encoding::BinaryLittleEndian => parser.read_little_endian_element(self.reader, def).map_err(|e| err(binary_problem(&e, def)))?,
                Encoding::BinaryBigEndian => parser.read_big_endian_element(self.reader, def).map_err(|e| err(binary_problem(&e, def)))?,
            };
            f(n, element)?;
        }
        Ok(())
    }
}

fn binary_problem(e: &ply_rs_bw::parser::ParseError, def: &ElementDef) -> String {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        format!("unexpected end of file; the header declares {} {} elements", def.count, def.name)
    } else {
        one_line(e)
    }
}

/// The names of the list of a face's vertex indices, preferred first.
const INDEX_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];

/// A vertex as read: x, y, z (the header guarantees the three scalars).
#[derive(Default)]
struct Vertex([f64; 3]);

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        match (["x", "y", "z"].into_iter().position(|a| a == name), scalar(&property)) {
            (Some(k), Some(v)) => {
                self.0[k] = v;
                PropertyAccessResult::Set
            }
            _ => PropertyAccessResult::Ignored,
        }
    }
}

/// A face as read: its lists named as in [`INDEX_NAMES`].
#[derive(Default)]
struct Face {
    lists: [Option<Property>; 2],
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        match INDEX_NAMES.into_iter().position(|n| n == name) {
            Some(k) => {
                self.lists[k] = Some(property);
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

/// An element of no interest, read past.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match p {
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

fn indices(p: &Property) -> Option<Vec<u32>> {
    fn all<T: Copy>(v: &[T], f: impl Fn(T) -> Option<u32>) -> Option<Vec<u32>> {
        v.iter().map(|&x| f(x)).collect()
    }
    match p {
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
