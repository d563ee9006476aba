//! STL, ASCII or binary. A binary file is recognised by its length (an
//! 80-byte header, a triangle count and 50 bytes a triangle) and read here;
//! anything else goes to `stl_io`, triangles one at a time so a lying count
//! allocates nothing. `stl_io` alone takes every file that begins with
//! "solid" for ASCII, and CAD exporters (SolidWorks among them) begin a
//! binary file's free-form header with that word.

use std::collections::HashMap;
use std::io::Cursor;

use crate::{TetraError, TriSurface};

/// Bytes before a binary STL's first triangle: header and triangle count.
const BINARY_HEADER: usize = 84;
/// Bytes of one binary triangle record: normal, three corners, attribute.
const BINARY_RECORD: usize = 50;

/// Parses STL bytes; vertices with bit-identical coordinates are shared.
pub(super) fn parse(bytes: &[u8]) -> Result<TriSurface, TetraError> {
    let mut surface = Indexed::default();
    if let Some(count) = binary_count(bytes) {
        for record in bytes[BINARY_HEADER..].chunks_exact(BINARY_RECORD).take(count) {
            let f = |k: usize| f32::from_le_bytes([record[k], record[k + 1], record[k + 2], record[k + 3]]);
            surface.push(std::array::from_fn(|v| std::array::from_fn(|c| f(12 + 12 * v + 4 * c))));
        }
    } else {
        let err = |e: std::io::Error| TetraError::Parse { format: "STL", message: e.to_string() };
        let mut cursor = Cursor::new(bytes);
        for tri in stl_io::create_stl_reader(&mut cursor).map_err(err)? {
            surface.push(tri.map_err(err)?.vertices.map(|v| v.0));
        }
    }
    let mut surface = surface.surface;
    surface.parts.push(("solid".to_string(), 0..surface.triangles.len()));
    Ok(surface)
}

/// The triangle count of a binary STL: `Some` when the file's length is
/// exactly its header and that many records. Text cannot pass by chance:
/// four letters read as the count ask for gigabytes.
fn binary_count(bytes: &[u8]) -> Option<usize> {
    let count = u32::from_le_bytes(bytes.get(80..BINARY_HEADER)?.try_into().ok()?) as usize;
    let expected = count.checked_mul(BINARY_RECORD)?.checked_add(BINARY_HEADER)?;
    (bytes.len() == expected).then_some(count)
}

/// A surface under construction whose corners are shared by bit-identical
/// coordinates.
#[derive(Default)]
struct Indexed {
    surface: TriSurface,
    index: HashMap<[u32; 3], usize>,
}

impl Indexed {
    fn push(&mut self, corners: [[f32; 3]; 3]) {
        let ids = corners.map(|p| {
            // `+ 0.0` makes −0 and +0 one key.
            let key = p.map(|c| (c + 0.0).to_bits());
            *self.index.entry(key).or_insert_with(|| {
                self.surface.vertices.push(p.map(f64::from));
                self.surface.vertices.len() - 1
            })
        });
        self.surface.triangles.push(ids);
    }
}
