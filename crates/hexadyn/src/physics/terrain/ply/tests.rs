//! PLY round trips of every format variant and malformed files.

use proptest::prelude::*;
use rand::Rng;

use super::*;
use crate::test_util::rng;

/// Random triangles with coordinates exact in f32 (so that float files round-trip exactly).
fn random_triangles(seed: u64, vertices: usize, faces: usize) -> Triangles {
    let mut r = rng(seed);
    Triangles {
        vertices: (0..vertices).map(|_| [(); 3].map(|_| r.random_range(-10.0f32..10.0) as f64)).collect(),
        faces: (0..faces).map(|_| [(); 3].map(|_| r.random_range(0..vertices as u32))).collect(),
    }
}

const ENCODINGS: [Encoding; 3] = [Encoding::Ascii, Encoding::BinaryLittleEndian, Encoding::BinaryBigEndian];

#[test]
fn round_trip_of_every_encoding_and_coordinate_type() {
    for (k, encoding) in ENCODINGS.into_iter().enumerate() {
        for double in [false, true] {
            let t = random_triangles(k as u64, 50, 80);
            let mut bytes = Vec::new();
            write(&t, PlyFormat { encoding, double }, &mut bytes).unwrap();
            assert_eq!(parse(&bytes, "t.ply").unwrap(), t, "{encoding:?}, double = {double}");
        }
    }
}

/// A file written by hand with the given face list types (count, index) and coordinate type.
fn handmade(t: &Triangles, encoding: Encoding, coordinate: &str, count: &str, index: &str) -> Vec<u8> {
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::BinaryLittleEndian => "binary_little_endian",
        Encoding::BinaryBigEndian => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment made by hand\nelement vertex {}\nproperty {coordinate} x\nproperty {coordinate} y\nproperty {coordinate} z\nproperty uchar red\nelement face {}\nproperty list {count} {index} vertex_indices\nend_header\n",
        t.vertices.len(),
        t.faces.len()
    )
    .into_bytes();
    let big = encoding == Encoding::BinaryBigEndian;
    let number = |out: &mut Vec<u8>, ty: &str, v: f64| {
        let b: Vec<u8> = match ty {
            "float" | "float32" => if big { (v as f32).to_be_bytes().to_vec() } else { (v as f32).to_le_bytes().to_vec() },
            "double" | "float64" => if big { v.to_be_bytes().to_vec() } else { v.to_le_bytes().to_vec() },
            "uchar" | "uint8" => vec![v as u8],
            "char" | "int8" => vec![v as i8 as u8],
            "ushort" | "uint16" => if big { (v as u16).to_be_bytes().to_vec() } else { (v as u16).to_le_bytes().to_vec() },
            "short" | "int16" => if big { (v as i16).to_be_bytes().to_vec() } else { (v as i16).to_le_bytes().to_vec() },
            "uint" | "uint32" => if big { (v as u32).to_be_bytes().to_vec() } else { (v as u32).to_le_bytes().to_vec() },
            "int" | "int32" => if big { (v as i32).to_be_bytes().to_vec() } else { (v as i32).to_le_bytes().to_vec() },
            _ => unreachable!("{ty}"),
        };
        out.extend(b);
    };
    for v in &t.vertices {
        if encoding == Encoding::Ascii {
            out.extend(format!("{} {} {} 7\n", v[0], v[1], v[2]).into_bytes());
        } else {
            for x in v {
                number(&mut out, coordinate, *x);
            }
            number(&mut out, "uchar", 7.0);
        }
    }
    for f in &t.faces {
        if encoding == Encoding::Ascii {
            out.extend(format!("3 {} {} {}\n", f[0], f[1], f[2]).into_bytes());
        } else {
            number(&mut out, count, 3.0);
            for &i in f {
                number(&mut out, index, i as f64);
            }
        }
    }
    out
}

#[test]
fn reads_every_list_type_in_every_encoding() {
    let t = random_triangles(9, 100, 120);
    for encoding in ENCODINGS {
        for coordinate in ["float", "double", "float32", "float64"] {
            for count in ["uchar", "uint8", "ushort", "uint", "char", "short", "int"] {
                for index in ["uchar", "char", "ushort", "short", "uint", "int", "uint32", "int32"] {
                    let bytes = handmade(&t, encoding, coordinate, count, index);
                    assert_eq!(parse(&bytes, "h.ply").unwrap(), t, "{encoding:?} {coordinate} list {count} {index}");
                }
            }
        }
    }
}

#[test]
fn polygons_are_cut_into_fans() {
    let text = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_index\nend_header\n0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n";
    let t = parse(text.as_bytes(), "poly.ply").unwrap();
    assert_eq!(t.faces, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
}

fn error(text: &str) -> PlyError {
    parse_terrain(text.as_bytes(), "bad.ply").unwrap_err()
}

const HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

#[test]
fn malformed_files_name_the_file_and_the_element() {
    let mut t = random_triangles(3, 3, 1);
    t.vertices[2][1] = f64::NAN;
    let mut bytes = Vec::new();
    write(&t, PlyFormat { encoding: Encoding::BinaryBigEndian, double: true }, &mut bytes).unwrap();
    let e = parse_terrain(&bytes, "bad.ply").unwrap_err();
    assert_eq!((e.element.as_str(), e.file.as_str()), ("vertex 2", "bad.ply"), "{e}");
    assert!(e.problem.contains("NaN"), "{e}");
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"));
    assert_eq!(e.element, "face 0", "{e}");
    assert!(e.problem.contains("out of range"), "{e}");
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"));
    assert!(e.element == "face 0" && e.problem.contains("degenerate"), "{e}");
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n0 1 0\n2 0 1\n"));
    assert!(e.element == "face 0" && e.problem.contains("at least 3"), "{e}");
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"));
    assert!(e.element == "face 0" && e.problem.contains("negative"), "{e}");
    // Truncated: a vertex short of the count.
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n"));
    assert_eq!((e.element.as_str(), e.problem.as_str()), ("vertex 2", "line 12: unexpected end of file; the header declares 3 vertex elements"), "{e}");
    let e = error(&format!("{HEADER}0 0 0\n1 0 0\n0 1\n"));
    assert!(e.element == "vertex 2" && e.problem.starts_with("line 12: "), "{e}");
    let e = error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n");
    assert!(e.element == "header" && e.problem.contains("`z`"), "{e}");
    let e = error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n");
    assert!(e.element == "header" && e.problem.contains("face"), "{e}");
    assert!(e.to_string().starts_with("bad.ply: header: "), "{e}");
}

/// A valid file and a mutation of it.
fn mutated() -> impl Strategy<Value = Vec<u8>> {
    let base = (0usize..3, any::<bool>(), 1u64..1000).prop_map(|(e, double, seed)| {
        let mut t = random_triangles(seed, 6, 5);
        t.faces.retain(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2]);
        let mut bytes = Vec::new();
        write(&t, PlyFormat { encoding: ENCODINGS[e], double }, &mut bytes).unwrap();
        bytes
    });
    (base, 0usize..6, any::<usize>(), any::<u8>(), any::<u32>()).prop_map(|(mut bytes, kind, at, byte, count)| {
        let end = bytes.windows(11).position(|w| w == b"end_header\n").map_or(0, |p| p + 11);
        match kind {
            // Truncated anywhere.
            0 => bytes.truncate(at % (bytes.len() + 1)),
            // One byte changed anywhere.
            1 => {
                let i = at % bytes.len();
                bytes[i] = byte;
            }
            // One byte changed in the payload.
            2 if end < bytes.len() => {
                let i = end + at % (bytes.len() - end);
                bytes[i] = byte;
            }
            // A count of the header changed.
            3 | 4 => {
                let text = String::from_utf8_lossy(&bytes[..end]).into_owned();
                let element = if kind == 3 { "element vertex " } else { "element face " };
                let start = text.find(element).unwrap() + element.len();
                let stop = start + text[start..].find('\n').unwrap();
                let header = format!("{}{}{}", &text[..start], count % 40, &text[stop..]);
                bytes = [header.into_bytes(), bytes[end..].to_vec()].concat();
            }
            // Garbage appended or a byte inserted.
            _ => bytes.insert(at % (bytes.len() + 1), byte),
        }
        bytes
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100_000, failure_persistence: None, ..ProptestConfig::default() })]

    /// Never a panic; an error is one line naming the file.
    #[test]
    fn malformed_files_give_one_clear_error(bytes in mutated()) {
        if let Err(e) = parse_terrain(&bytes, "fuzz.ply") {
            let message = e.to_string();
            prop_assert!(message.starts_with("fuzz.ply: "), "{}", message);
            prop_assert!(!message.contains('\n'), "{}", message);
            prop_assert!(!e.element.is_empty() && !e.problem.is_empty(), "{}", message);
        }
    }
}

/// What ply-rs's whole-file reader finds in `bytes`: the vertices and the fans of the faces,
/// the reference the streaming reader is held to.
fn whole_file_reading(bytes: &[u8]) -> Triangles {
    let ply = ply_rs_bw::parser::Parser::<DefaultElement>::new().read_ply(&mut &bytes[..]).unwrap();
    let vertices = ply.payload["vertex"].iter().map(|v| ["x", "y", "z"].map(|a| scalar(&v[a]).unwrap())).collect();
    let mut faces = Vec::new();
    for f in &ply.payload["face"] {
        let i = indices(f.get("vertex_indices").or_else(|| f.get("vertex_index")).unwrap()).unwrap();
        faces.extend((1..i.len() - 1).map(|k| [i[0], i[k], i[k + 1]]));
    }
    Triangles { vertices, faces }
}

#[test]
fn streaming_reads_what_the_whole_file_reader_reads() {
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/terrains");
    for entry in std::fs::read_dir(&folder).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(parse(&bytes, "shipped.ply").unwrap(), whole_file_reading(&bytes), "{}", path.display());
        assert_eq!(read_terrain(&path).unwrap().triangle_count(), whole_file_reading(&bytes).faces.len(), "{}", path.display());
    }
    // Other elements and properties before, between and after, in every encoding.
    let t = random_triangles(4, 30, 40);
    for encoding in ENCODINGS {
        let bytes = handmade(&t, encoding, "double", "uchar", "int");
        assert_eq!(parse(&bytes, "h.ply").unwrap(), whole_file_reading(&bytes), "{encoding:?}");
    }
    let text = "ply\nformat ascii 1.0\nelement camera 2\nproperty float f\nproperty list uchar float k\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement edge 1\nproperty int a\nelement face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\nelement empty 5\nend_header\n1 2 0.5 0.25\n2 0\n0 0 0\n1 0 0\n0 1 0\n7\n1 3 0 1 2\n\n\n\n\n\n";
    assert_eq!(parse(text.as_bytes(), "e.ply").unwrap(), whole_file_reading(text.as_bytes()));
}

/// Headers declaring more than the file holds, or than a terrain may have, are refused from
/// the header, without reading (nor reserving memory for) the elements.
#[test]
fn declared_counts_are_checked_before_reading() {
    let declared = |format: &str, vertices: u64, faces: u64| format!("ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n");
    let e = parse(declared("binary_little_endian", 1_000_000_000, 1).as_bytes(), "big.ply").unwrap_err();
    assert_eq!(e.element, "header", "{e}");
    assert!(e.problem.starts_with("`element vertex 1000000000` of at least 12 bytes each: the elements up to it need at least 12000000000 bytes, more than the file's 178"), "{e}");
    let e = parse(declared("ascii", 3, 1 << 40).as_bytes(), "big.ply").unwrap_err();
    assert!(e.problem.contains("`element face 1099511627776` of at least 2 bytes each"), "{e}");
    // Held by the file, beyond the bounds.
    let mut bytes = declared("binary_little_endian", MAX_MESH_VERTICES as u64 + 1, 1).into_bytes();
    bytes.resize(bytes.len() + 12 * (MAX_MESH_VERTICES + 1) + 13, 0);
    let e = parse(&bytes, "big.ply").unwrap_err();
    assert_eq!(e.to_string(), format!("big.ply: header: `element vertex {}`: too many; allowed: at most {MAX_MESH_VERTICES} (hexadyn's bound on a terrain mesh, MAX_MESH_VERTICES)", MAX_MESH_VERTICES + 1));
}

#[test]
fn unbounded_lines_are_refused() {
    let e = parse(format!("ply\nformat ascii 1.0\ncomment {}", "x".repeat(70_000)).as_bytes(), "long.ply").unwrap_err();
    assert!(e.element == "header" && e.problem.starts_with("no `end_header` in the first 65536 bytes"), "{e}");
    let e = parse(format!("{HEADER}0 0 0 {}\n", "1 ".repeat(40_000)).as_bytes(), "long.ply").unwrap_err();
    assert_eq!((e.element.as_str(), e.problem.as_str()), ("vertex 0", "line 10: longer than 65536 bytes; allowed: a line of numbers"), "{e}");
}
