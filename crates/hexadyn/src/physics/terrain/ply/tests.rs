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
    assert!(e.element.starts_with("line"), "{e}");
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
