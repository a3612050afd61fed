//! Writes the shipped terrains (`hexadyn::physics::terrain::generate::shipped`) as PLY files into
//! the folder given as argument (`make terrains`: `python/hexadyn/scenarios/terrains`).

use std::path::PathBuf;

use hexadyn::physics::terrain::{generate, ply};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let folder = PathBuf::from(std::env::args().nth(1).ok_or("usage: make_terrains FOLDER")?);
    std::fs::create_dir_all(&folder)?;
    for (name, triangles) in generate::shipped() {
        let path = folder.join(name);
        let mut bytes = Vec::new();
        ply::write(&triangles, generate::SHIPPED_FORMAT, &mut bytes)?;
        // Written next to the target, then renamed: never a half-written terrain.
        let partial = path.with_extension("ply.partial");
        std::fs::write(&partial, &bytes)?;
        std::fs::rename(&partial, &path)?;
        println!("{}: {} triangles, {} bytes", path.display(), triangles.faces.len(), bytes.len());
    }
    Ok(())
}
