//! Geomview OFF (ASCII), the format of the Princeton Shape Benchmark and of
//! ModelNet: a header keyword, the counts `V F E`, `V` lines of `x y z`,
//! then `F` lines of `n i₁ … iₙ`; polygons are triangulated by `polygon`.
//!
//! Written here rather than through the `off-rs` crate, which reads
//! coordinates as `f32` (a CAD export's micrometre detail lost at metre
//! scale) and refuses ModelNet's files, thousands of which fuse the keyword
//! with the counts (`OFF1234 2468 0` on one line). Read as well: the
//! `C`/`N`/`ST` prefixes (per-vertex colours, normals and texture
//! coordinates after `x y z`, ignored, as are a face's colour values after
//! its indices), `#` comments and blank lines anywhere. Refused with a
//! clear error: binary OFF, other dimensions than 3 (`4OFF`, `nOFF`), and
//! counts the file cannot hold (nothing is allocated for them first).

use super::polygon::Triangulator;
use crate::{TetraError, TriSurface};

fn bad(message: impl Into<String>) -> TetraError {
    TetraError::Parse { format: "OFF", message: message.into() }
}

/// The file's tokens, line by line (comments and blank lines dropped), so
/// errors can name a line.
struct Tokens<'a> {
    lines: std::iter::Peekable<std::iter::Enumerate<std::str::Lines<'a>>>,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str) -> Self {
        Tokens { lines: text.lines().enumerate().peekable() }
    }

    /// The next line that holds something: (1-based line number, its words).
    fn next_line(&mut self) -> Option<(usize, Vec<&'a str>)> {
        for (i, line) in self.lines.by_ref() {
            let content = line.split('#').next().unwrap_or("");
            let words: Vec<&str> = content.split_whitespace().collect();
            if !words.is_empty() {
                return Some((i + 1, words));
            }
        }
        None
    }
}

fn number<T: std::str::FromStr>(word: &str, line: usize, what: &str) -> Result<T, TetraError> {
    word.parse().map_err(|_| bad(format!("line {line}: {what} '{word}' is not a number")))
}

/// Parses OFF bytes into one part named "off".
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let text = std::str::from_utf8(bytes).map_err(|_| bad("not a text file (binary OFF is not read)"))?;
    let mut tokens = Tokens::new(text);
    let (line, mut words) = tokens.next_line().ok_or_else(|| bad("the file is empty"))?;
    let keyword = header_keyword(words[0], line)?;
    // ModelNet: "OFF1234 2468 0" is the keyword and the counts on one line.
    let fused = &words[0][keyword.len()..];
    words = if fused.is_empty() { words[1..].to_vec() } else { [&[fused], &words[1..]].concat() };
    if words.first() == Some(&"BINARY") {
        return Err(bad("binary OFF is not read (write it as ASCII OFF, OBJ or PLY)"));
    }
    let (line, counts) = if words.is_empty() {
        tokens.next_line().ok_or_else(|| bad("no vertex and face counts after the header"))?
    } else {
        (line, words)
    };
    if counts.len() < 2 {
        return Err(bad(format!("line {line}: expected the counts 'vertices faces [edges]'")));
    }
    let vertex_count: usize = number(counts[0], line, "vertex count")?;
    let face_count: usize = number(counts[1], line, "face count")?;
    // Each vertex needs at least 6 bytes ("0 0 0\n"), each face 8 ("3 0 1 2\n").
    if vertex_count.saturating_mul(6).saturating_add(face_count.saturating_mul(8)) > bytes.len() {
        return Err(bad(format!(
            "line {line}: {vertex_count} vertices and {face_count} faces do not fit in a file of {} bytes",
            bytes.len()
        )));
    }
    let mut surface = TriSurface::default();
    surface.vertices.reserve(vertex_count);
    for v in 0..vertex_count {
        let (line, words) = tokens
            .next_line()
            .ok_or_else(|| bad(format!("the file ends after {v} of {vertex_count} vertices")))?;
        if words.len() < 3 {
            return Err(bad(format!("line {line}: vertex {v} needs x y z")));
        }
        let coordinate = |k: usize| number::<f64>(words[k], line, "coordinate");
        surface.vertices.push([coordinate(0)?, coordinate(1)?, coordinate(2)?]);
    }
    let mut triangulator = Triangulator::new();
    for f in 0..face_count {
        let (line, words) = tokens
            .next_line()
            .ok_or_else(|| bad(format!("the file ends after {f} of {face_count} faces")))?;
        let corners: usize = number(words[0], line, "corner count")?;
        if corners < 3 {
            return Err(TetraError::BadFace { face: f, corners });
        }
        if words.len() < 1 + corners {
            return Err(bad(format!(
                "line {line}: face {f} names {} of its {corners} corners",
                words.len() - 1
            )));
        }
        let mut ids = Vec::with_capacity(corners);
        for word in &words[1..=corners] {
            let vertex: usize = number(word, line, "vertex index")?;
            if vertex >= vertex_count {
                return Err(TetraError::IndexOutOfRange { triangle: f, vertex, count: vertex_count });
            }
            ids.push(vertex);
        }
        triangulator.push(&surface.vertices, &ids, &mut surface.triangles);
    }
    surface.parts.push(("off".to_string(), 0..surface.triangles.len()));
    Ok(surface)
}

/// The header keyword at the start of `word`: `OFF` with an optional
/// `ST`, `C`, `N` prefix in that order (Geomview's `[ST][C][N][4][n]OFF`);
/// the 4- and n-dimensional forms are refused.
fn header_keyword(word: &str, line: usize) -> Result<&str, TetraError> {
    let Some(at) = word.find("OFF") else {
        return Err(bad(format!("line {line}: the file does not start with an OFF header (found '{word}')")));
    };
    let prefix = &word[..at];
    if prefix.ends_with('4') || prefix.ends_with('n') {
        return Err(bad(format!("line {line}: '{prefix}OFF' is not 3-dimensional; only 3-D OFF is read")));
    }
    let known = ["", "C", "N", "CN", "ST", "STC", "STN", "STCN"];
    if !known.contains(&prefix) {
        return Err(bad(format!("line {line}: unknown OFF header '{}'", &word[..at + 3])));
    }
    Ok(&word[..at + 3])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fused_modelnet_header_and_coloured_faces_are_read() {
        let text = "OFF4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1 255 0 0\n4 0 1 3 2 # quad\n";
        let s = parse(text.as_bytes()).unwrap();
        assert_eq!(s.vertices.len(), 4);
        assert_eq!(s.triangles, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]]);
    }

    #[test]
    fn prefixes_comments_and_split_headers_are_read_and_bad_files_refused() {
        let text =
            "# a tetrahedron\nCOFF\n\n4 4 6\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n0 0 1 1 1 1 1\n\
                    3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
        assert_eq!(parse(text.as_bytes()).unwrap().triangles.len(), 4);
        let refused = |t: &str| parse(t.as_bytes()).unwrap_err().to_string();
        assert!(refused("OFF BINARY\n").contains("binary"));
        assert!(refused("4OFF\n1 0\n0 0 0 0\n").contains("3-dimensional"));
        assert!(refused("PLY\n").contains("OFF header"));
        assert!(refused("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").contains("only 3 vertices"));
        let truncated = "OFF\n3 1 0\n0 0 0\n1 0 0\n# cut off here, after two of the three vertices\n";
        assert!(refused(truncated).contains("ends after 2 of 3 vertices"));
        assert!(refused("OFF\n99999999999 1 0\n").contains("do not fit"));
        assert!(refused("OFF\n1 0 0\n0 0 x\n").contains("'x' is not a number"));
        assert!(refused("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n").contains("corner"));
    }
}
