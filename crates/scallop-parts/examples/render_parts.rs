//! Writes the pictures of the three test parts for docs/guides.md:
//! `cargo run -p scallop-parts --example render_parts -- docs/img`.
//! Cut-away views: faces turned to the eye (near flanks, the lid) drop out.

use scallop_parts::{FaceTag, TestPart, closed_pocket, fitting_pocket, impeller_channel, svg_view};

fn colour(tag: FaceTag) -> Option<[u8; 3]> {
    match tag {
        FaceTag::Bottom => Some([90, 150, 230]),
        FaceTag::Flank => Some([235, 160, 80]),
        FaceTag::Top => Some([170, 170, 170]),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "docs/img".into());
    let parts: [(&str, TestPart); 3] = [
        ("part-closed-pocket.svg", closed_pocket(&Default::default())?),
        ("part-impeller-channel.svg", impeller_channel(&Default::default())?),
        ("part-fitting-pocket.svg", fitting_pocket(&Default::default())?),
    ];
    for (name, part) in parts {
        let svg = svg_view(&part.mesh, 640.0, |t| colour(part.tags[t]));
        let path = std::path::Path::new(&dir).join(name);
        std::fs::write(&path, svg)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
