//! The figures committed in `plots/` are what the documented commands draw now.
//!
//! `docs_run` runs every command block of README.md and docs/*.md; after each block, every
//! figure it names under `plots/` that is also committed is compared here with the committed
//! file: an SVG as text (line endings normalised; the program writes nothing else that varies
//! between runs: no date, no version, no random id), a PNG by its decoded pixels (so another
//! encoder setting of the same picture is not a difference). A committed figure that no run
//! block draws fails, unless its block was skipped (its data, `../shared`, are not beside the
//! repository, or it needs Python) or it is listed in [`NOT_REDRAWN`] with the reason.

use crate::common::repo;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Committed figures that no test can redraw identically, and why.
pub const NOT_REDRAWN: [(&str, &str); 2] = [
    (
        "methods.png",
        "`tiltnoise methods --save plots/methods.png`: times measured on the machine that drew it",
    ),
    (
        "methods.svg",
        "`tiltnoise methods --save plots/methods.svg`: times measured on the machine that drew it",
    ),
];

/// The figures a script names under `plots/` (`plots/NAME.png`, `plots/NAME.svg`), as `NAME.ext`.
pub fn figures_named(script: &str) -> Vec<String> {
    let mut names: Vec<String> = script
        .split(|c: char| c.is_whitespace() || matches!(c, '=' | '"' | '\'' | '(' | ')'))
        .filter_map(|word| word.strip_prefix("plots/"))
        .filter(|name| name.ends_with(".png") || name.ends_with(".svg"))
        .map(str::to_string)
        .collect();
    names.sort();
    names.dedup();
    names
}

/// The committed figures: the PNG and SVG files of the repository's `plots/`, by name.
pub fn committed() -> BTreeMap<String, PathBuf> {
    std::fs::read_dir(repo("plots"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png" || e == "svg"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), p))
        .collect()
}

/// An image's pixels as 8-bit RGBA, row by row, with its width and height.
struct Pixels {
    width: u32,
    height: u32,
    rgba: Vec<u8>,
}

fn decode_png(path: &Path) -> Result<Pixels, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    // Palettes and low bit depths to 8-bit samples; 16-bit samples are cut to their high byte.
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("{}: not a PNG: {e}", path.display()))?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let samples = &buf[..frame.buffer_size()];
    let rgba: Vec<u8> = match frame.color_type {
        png::ColorType::Rgba => samples.to_vec(),
        png::ColorType::Rgb => samples
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        png::ColorType::GrayscaleAlpha => samples
            .chunks_exact(2)
            .flat_map(|p| [p[0], p[0], p[0], p[1]])
            .collect(),
        png::ColorType::Grayscale => samples.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::Indexed => {
            return Err(format!("{}: palette left after expansion", path.display()))
        }
    };
    Ok(Pixels {
        width: frame.width,
        height: frame.height,
        rgba,
    })
}

/// Why the PNG `drawn` and `committed` are not the same picture, or nothing.
fn png_difference(drawn: &Path, committed: &Path) -> Result<Option<String>, String> {
    let (a, b) = (decode_png(drawn)?, decode_png(committed)?);
    if (a.width, a.height) != (b.width, b.height) {
        return Ok(Some(format!(
            "{}x{} pixels drawn, {}x{} committed",
            a.width, a.height, b.width, b.height
        )));
    }
    let (mut count, mut x_range, mut y_range) = (0usize, (u32::MAX, 0), (u32::MAX, 0));
    for (k, (p, q)) in a
        .rgba
        .chunks_exact(4)
        .zip(b.rgba.chunks_exact(4))
        .enumerate()
    {
        if p != q {
            let (x, y) = (k as u32 % a.width, k as u32 / a.width);
            count += 1;
            x_range = (x_range.0.min(x), x_range.1.max(x));
            y_range = (y_range.0.min(y), y_range.1.max(y));
        }
    }
    Ok((count > 0).then(|| {
        format!(
            "{count} of {} pixels differ, in x {}..{}, y {}..{}",
            a.width as usize * a.height as usize,
            x_range.0,
            x_range.1,
            y_range.0,
            y_range.1
        )
    }))
}

/// An SVG's text with its line endings normalised.
fn svg_text(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(text.replace("\r\n", "\n"))
}

/// Why the SVG `drawn` and `committed` are not the same figure, or nothing.
fn svg_difference(drawn: &Path, committed: &Path) -> Result<Option<String>, String> {
    let (a, b) = (svg_text(drawn)?, svg_text(committed)?);
    if a == b {
        return Ok(None);
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let first = la
        .iter()
        .zip(&lb)
        .position(|(x, y)| x != y)
        .unwrap_or(la.len().min(lb.len()));
    let line = |lines: &[&str]| {
        lines
            .get(first)
            .map(|l| l.chars().take(160).collect::<String>())
            .unwrap_or_else(|| "(end of file)".to_string())
    };
    Ok(Some(format!(
        "{} lines drawn, {} committed; first difference at line {}:\n  drawn:     {}\n  committed: {}",
        la.len(),
        lb.len(),
        first + 1,
        line(&la),
        line(&lb)
    )))
}

/// Why the figure `drawn` differs from the committed one, or nothing when they are the same.
pub fn difference(drawn: &Path, committed: &Path) -> Result<Option<String>, String> {
    match drawn.extension().and_then(|e| e.to_str()) {
        Some("png") => png_difference(drawn, committed),
        Some("svg") => svg_difference(drawn, committed),
        other => Err(format!("{}: not a figure ({other:?})", drawn.display())),
    }
}

/// Writes `pixels` (RGBA, `width` x `height`) as a PNG of `color` (Rgb or Rgba).
#[cfg(test)]
fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8], color: png::ColorType) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = match color {
        png::ColorType::Rgba => rgba.to_vec(),
        png::ColorType::Rgb => rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect(),
        _ => unreachable!(),
    };
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&data).unwrap();
}

#[test]
fn a_figure_is_the_same_when_its_pixels_or_text_are_and_differs_by_one_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (5u32, 3u32);
    let picture: Vec<u8> = (0..w * h)
        .flat_map(|k| [(k * 17) as u8, (k * 5) as u8, 200, 255])
        .collect();
    let rgba = dir.path().join("a.png");
    let rgb = dir.path().join("b.png");
    write_png(&rgba, w, h, &picture, png::ColorType::Rgba);
    write_png(&rgb, w, h, &picture, png::ColorType::Rgb);
    assert_ne!(std::fs::read(&rgba).unwrap(), std::fs::read(&rgb).unwrap());
    assert_eq!(
        difference(&rgba, &rgb).unwrap(),
        None,
        "same pixels, two encodings"
    );

    let mut changed = picture.clone();
    let k = (2 * w + 3) as usize * 4; // pixel x 3, y 2
    changed[k + 1] ^= 1;
    let one_off = dir.path().join("c.png");
    write_png(&one_off, w, h, &changed, png::ColorType::Rgba);
    assert_eq!(
        difference(&one_off, &rgb).unwrap().as_deref(),
        Some("1 of 15 pixels differ, in x 3..3, y 2..2")
    );
    let smaller = dir.path().join("d.png");
    write_png(
        &smaller,
        w,
        h - 1,
        &picture[..(w * (h - 1) * 4) as usize],
        png::ColorType::Rgba,
    );
    assert_eq!(
        difference(&smaller, &rgb).unwrap().as_deref(),
        Some("5x2 pixels drawn, 5x3 committed")
    );

    let svg = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let unix = svg("a.svg", "<svg>\n<text>1e-3</text>\n</svg>\n");
    let dos = svg("b.svg", "<svg>\r\n<text>1e-3</text>\r\n</svg>\r\n");
    let other = svg("c.svg", "<svg>\n<text>2e-3</text>\n</svg>\n");
    assert_eq!(difference(&unix, &dos).unwrap(), None);
    let why = difference(&other, &unix).unwrap().unwrap();
    assert!(
        why.contains("line 2") && why.contains("2e-3") && why.contains("1e-3"),
        "{why}"
    );
}

#[test]
fn the_figures_a_script_names_are_found_in_its_options() {
    assert_eq!(
        figures_named(
            "tiltnoise tf --save plots/tilt_tf.png --save=plots/tilt_tf.svg --save tilt_tf.h5\n\
             tiltnoise simulate --save-time plots/kick.png --save plots/x.csv"
        ),
        vec!["kick.png", "tilt_tf.png", "tilt_tf.svg"]
    );
}
