//! glTF 2.0 (`.glb`, or `.gltf` with its buffers in files next to it)
//! through the `gltf` crate: the triangles of every mesh the default scene
//! (else the first, else every root node) places, in world coordinates.
//!
//! A node's world matrix is its parents' times its own (`T·R·S` or the
//! given matrix, glTF §5.25); positions are `M·[x y z 1]ᵀ` in metres, the
//! format's unit. A mirroring matrix (`det M < 0`) reverses the triangles'
//! winding, so they still face out. Triangle strips and fans are split into
//! triangles; points and lines are skipped. Each placed mesh becomes a part
//! named after its node (else its mesh, else `mesh N`).
//!
//! Quantized positions (`KHR_mesh_quantization`, what `gltfpack` writes by
//! default: 8- or 16-bit integers, normalized or not, scaled back by the
//! node's matrix) are read as the extension says; extensions a file
//! requires for what is not geometry (textures, materials) do not stop it.
//! Buffers are the GLB's binary chunk, `data:` URIs, or files named by
//! relative, percent-encoded paths (see the `uri` module); of a file,
//! only the declared `byteLength` is read.
//! Refused with a clear error rather than read wrongly: compressed
//! geometry (`KHR_draco_mesh_compression`, `EXT_meshopt_compression`:
//! decompress first), buffers shorter than declared, buffer URIs that are
//! absolute or of another scheme, buffer paths that are not regular files
//! (a device such as `/dev/zero` or a FIFO would be read without end, or
//! waited on), indices out of range, node hierarchies deeper than
//! [`MAX_DEPTH`] (or cyclic), and every other error of the document's
//! validation.

use std::io::Read;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;

use super::uri::{self, BufferUri};
use crate::{TetraError, TriSurface};

/// Deepest node hierarchy followed (a cycle would be endless).
pub const MAX_DEPTH: usize = 64;

fn bad(message: impl Into<String>) -> TetraError {
    TetraError::Parse { format: "glTF", message: message.into() }
}

type Matrix = [[f64; 4]; 4];

/// Parses glTF bytes; `base` is the folder of a `.gltf` whose buffers are files.
pub(super) fn parse(bytes: &[u8], base: Option<&Path>) -> Result<TriSurface, TetraError> {
    let doc = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| bad(e.to_string()))?;
    validate(&doc).map_err(|e| bad(with_compression_hint(bytes, e)))?;
    let buffers = gltf_buffers(&doc, base, bytes)?;
    let mut surface = TriSurface::default();
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let children: std::collections::HashSet<usize> =
                doc.nodes().flat_map(|n| n.children().map(|c| c.index()).collect::<Vec<_>>()).collect();
            doc.nodes().filter(|n| !children.contains(&n.index())).collect()
        }
    };
    let identity: Matrix = std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j))));
    for node in roots {
        place(&node, &identity, 0, &buffers, &mut surface)?;
    }
    if surface.triangles.is_empty() {
        return Err(bad("the scene places no triangles (only points or lines, or no meshes)"));
    }
    Ok(surface)
}

/// Compressed geometry: extensions the `gltf` crate does not decode.
const UNDECODED: [&str; 2] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

/// The document's validation (indices in range, required fields), less its
/// refusal of required extensions it does not know: a file that needs
/// `KHR_texture_basisu` for its textures or `KHR_mesh_quantization` (read
/// here) has geometry all the same. The first error, as the crate says it.
fn validate(doc: &gltf::Gltf) -> Result<(), String> {
    use ::gltf::json::validation::{Error, Validate};
    let root = doc.as_json();
    let mut first = None;
    root.validate(root, ::gltf::json::Path::new, &mut |path, error| {
        let path = path();
        let unknown_extension =
            path.as_str().starts_with("extensionsRequired") && error == Error::Unsupported;
        if first.is_none() && !unknown_extension {
            first = Some(format!("invalid glTF: {}: {error}", path.as_str()));
        }
    });
    first.map_or(Ok(()), Err)
}

/// `message`, and which undecoded extension the file names, if any (a Draco
/// file's accessors have no data of their own, which the crate reports as
/// missing data).
fn with_compression_hint(bytes: &[u8], message: String) -> String {
    match UNDECODED.iter().find(|ext| bytes.windows(ext.len()).any(|w| w == ext.as_bytes())) {
        Some(ext) => {
            format!("{message} (the file uses {ext}: decompress it first, e.g. with gltf-transform)")
        }
        None => message,
    }
}

/// Every buffer's bytes, in the document's order: buffer 0 may be the GLB's
/// binary chunk, any buffer a `data:` URI or a file named by its URI relative
/// to `base` (the folder of a `.gltf`; `None` refuses external files), of
/// which the declared length is read. `bytes` is the whole file, for the
/// error's hint. Refused: a buffer other than 0 without a URI (a compressed
/// file's fallback, which holds no data), URIs that are neither relative
/// paths nor `data:`, paths that are not regular files, and buffers shorter
/// than they declare. Shared by the geometry reader here and the bank import
/// of `modal-export`, so both read a container alike.
pub fn gltf_buffers(doc: &gltf::Gltf, base: Option<&Path>, bytes: &[u8]) -> Result<Vec<Vec<u8>>, TetraError> {
    doc.buffers()
        .map(|buffer| {
            let data = match buffer.source() {
                // A compressed file's fallback buffer has no data and no URI either.
                gltf::buffer::Source::Bin if buffer.index() > 0 => {
                    let message =
                        format!("buffer {} has no data (only buffer 0 is the GLB's chunk)", buffer.index());
                    return Err(bad(with_compression_hint(bytes, message)));
                }
                gltf::buffer::Source::Bin => doc
                    .blob
                    .clone()
                    .ok_or_else(|| bad("buffer 0 is the GLB's binary chunk, but there is none"))?,
                gltf::buffer::Source::Uri(uri) => uri_bytes(buffer.index(), uri, buffer.length(), base)?,
            };
            if data.len() < buffer.length() {
                return Err(bad(format!(
                    "buffer {} holds {} bytes, {} declared",
                    buffer.index(),
                    data.len(),
                    buffer.length()
                )));
            }
            Ok(data)
        })
        .collect()
}

/// The bytes of the buffers the glTF file at `path` names by URI (files
/// next to it, `data:` URIs), in the document's order; not the GLB's own
/// binary chunk, which is part of the file. With the file's own bytes they
/// are everything its geometry is read from: what a cache key must hash (a
/// `.gltf` whose `.bin` was exported again is another mesh).
pub fn gltf_uri_buffers(path: &Path) -> Result<Vec<Vec<u8>>, TetraError> {
    let bytes = std::fs::read(path).map_err(|source| TetraError::Io { path: path.to_path_buf(), source })?;
    let doc = gltf::Gltf::from_slice(&bytes).map_err(|e| bad(e.to_string()))?;
    let base = path.parent().unwrap_or(Path::new("."));
    doc.buffers()
        .filter_map(|buffer| match buffer.source() {
            gltf::buffer::Source::Uri(uri) => {
                Some(uri_bytes(buffer.index(), uri, buffer.length(), Some(base)))
            }
            gltf::buffer::Source::Bin => None,
        })
        .collect()
}

/// The bytes of buffer `index`, whose URI is `uri` and declared length `length`.
fn uri_bytes(index: usize, uri: &str, length: usize, base: Option<&Path>) -> Result<Vec<u8>, TetraError> {
    match uri::parse(uri).map_err(|why| bad(format!("buffer {index}: {why}")))? {
        BufferUri::Data(data) => Ok(data),
        BufferUri::Relative(relative) => {
            let base = base.ok_or_else(|| bad(format!("buffer {index}: '{uri}' is an external file")))?;
            read_prefix(index, &base.join(relative), length)
        }
    }
}

/// The first `length` bytes of the file `path` (buffer `index`). Its
/// metadata is looked at before it is opened: a device such as `/dev/zero`
/// would be read until memory runs out, a FIFO waited on, so only a regular
/// file is read; and one shorter than `length` is refused before `length`
/// bytes (declared by the file, so possibly absurd) are allocated.
fn read_prefix(index: usize, path: &Path, length: usize) -> Result<Vec<u8>, TetraError> {
    let io = |source| TetraError::Io { path: path.to_path_buf(), source };
    let metadata = std::fs::metadata(path).map_err(io)?;
    if !metadata.is_file() {
        let kind = if metadata.is_dir() { "a directory" } else { "not a regular file" };
        return Err(bad(format!("buffer {index}: {} is {kind}", path.display())));
    }
    let short = |size: u64| {
        bad(format!("buffer {index}: file {} has {size} bytes, the glTF declares {length}", path.display()))
    };
    if metadata.len() < length as u64 {
        return Err(short(metadata.len()));
    }
    let mut data = Vec::new();
    data.try_reserve_exact(length)
        .map_err(|_| bad(format!("buffer {index}: its {length} bytes do not fit in memory")))?;
    let file = std::fs::File::open(path).map_err(io)?;
    file.take(length as u64).read_to_end(&mut data).map_err(io)?;
    // The file may have shrunk since its metadata was read.
    if data.len() < length {
        return Err(short(data.len() as u64));
    }
    Ok(data)
}

/// Adds the triangles of `node` and its children under the parent matrix `parent`.
fn place(
    node: &gltf::Node,
    parent: &Matrix,
    depth: usize,
    buffers: &[Vec<u8>],
    surface: &mut TriSurface,
) -> Result<(), TetraError> {
    if depth >= MAX_DEPTH {
        return Err(bad(format!("the node hierarchy is deeper than {MAX_DEPTH} (or cyclic)")));
    }
    let local = node.transform().matrix().map(|column| column.map(f64::from));
    let world = multiply(parent, &local);
    if let Some(mesh) = node.mesh() {
        let name =
            node.name().or(mesh.name()).map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
        let first = surface.triangles.len();
        for primitive in mesh.primitives() {
            add_primitive(&primitive, &world, buffers, surface)?;
        }
        if surface.triangles.len() > first {
            surface.parts.push((name, first..surface.triangles.len()));
        }
    }
    for child in node.children() {
        place(&child, &world, depth + 1, buffers, surface)?;
    }
    Ok(())
}

/// Adds one primitive's triangles, positions mapped by `world`.
fn add_primitive(
    primitive: &gltf::Primitive,
    world: &Matrix,
    buffers: &[Vec<u8>],
    surface: &mut TriSurface,
) -> Result<(), TetraError> {
    if matches!(primitive.mode(), Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
        return Ok(());
    }
    let positions = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| bad("a triangle primitive has no POSITION attribute"))?;
    if positions.view().is_none() || positions.dimensions() != Dimensions::Vec3 {
        return Err(bad(
            "positions without data of their own or not 3-vectors (compressed: KHR_draco_mesh_compression or \
             EXT_meshopt_compression; decompress the file first)",
        ));
    }
    if primitive
        .indices()
        .is_some_and(|i| !matches!(i.data_type(), DataType::U8 | DataType::U16 | DataType::U32))
    {
        return Err(bad("indices that are not unsigned integers"));
    }
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
    let reader = primitive.reader(get);
    let local = positions_of(&positions, get)?;
    let offset = surface.vertices.len();
    surface.vertices.extend(local.into_iter().map(|p| transform(world, p)));
    let count = surface.vertices.len() - offset;
    let indices: Vec<usize> = match primitive.indices() {
        Some(_) => {
            let read = reader.read_indices().ok_or_else(|| bad("indices reach past their buffer"))?;
            read.into_u32().map(|i| i as usize).collect()
        }
        None => (0..count).collect(),
    };
    if let Some(&i) = indices.iter().find(|&&i| i >= count) {
        return Err(bad(format!("index {i} beyond the primitive's {count} positions")));
    }
    let mirrored = determinant3(world) < 0.0;
    for t in triangles(primitive.mode(), &indices) {
        let [a, b, c] = t.map(|i| offset + i);
        surface.triangles.push(if mirrored { [a, c, b] } else { [a, b, c] });
    }
    Ok(())
}

/// The positions of `accessor` in the mesh's own frame: 32-bit floats, or the
/// integers of `KHR_mesh_quantization`, normalized ones mapped to [−1, 1] or
/// [0, 1] as glTF §3.11 says (`max(c / (2ⁿ⁻¹ − 1), −1)`, `c / (2ⁿ − 1)`).
fn positions_of<'a, 's>(
    accessor: &gltf::Accessor<'a>,
    get: impl Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
) -> Result<Vec<[f64; 3]>, TetraError> {
    fn read<'a, 's, T: Copy>(
        accessor: &gltf::Accessor<'a>,
        get: impl Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
        scale: impl Fn(T) -> f64,
    ) -> Result<Vec<[f64; 3]>, TetraError>
    where
        [T; 3]: ::gltf::accessor::Item,
    {
        let iter = ::gltf::accessor::Iter::<[T; 3]>::new(accessor.clone(), get)
            .ok_or_else(|| bad("positions reach past their buffer"))?;
        Ok(iter.map(|p| p.map(&scale)).collect())
    }
    let n = accessor.normalized();
    let signed = |c: f64, max: f64| if n { (c / max).max(-1.0) } else { c };
    let unsigned = |c: f64, max: f64| if n { c / max } else { c };
    match accessor.data_type() {
        DataType::F32 => read::<f32>(accessor, get, f64::from),
        DataType::I16 => read::<i16>(accessor, get, |c| signed(f64::from(c), 32767.0)),
        DataType::U16 => read::<u16>(accessor, get, |c| unsigned(f64::from(c), 65535.0)),
        DataType::I8 => read::<i8>(accessor, get, |c| signed(f64::from(c), 127.0)),
        DataType::U8 => read::<u8>(accessor, get, |c| unsigned(f64::from(c), 255.0)),
        DataType::U32 => Err(bad("positions of 32-bit integers (no extension allows them)")),
    }
}

/// The triangles (counter-clockwise) of a triangle list, strip or fan.
fn triangles(mode: Mode, indices: &[usize]) -> Vec<[usize; 3]> {
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                let (a, b, c) = (indices[k - 2], indices[k - 1], indices[k]);
                if k % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len()).map(|k| [indices[0], indices[k - 1], indices[k]]).collect(),
        _ => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// `a · b` of column-major 4 × 4 matrices (`m[column][row]`, as glTF stores them).
fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    std::array::from_fn(|col| std::array::from_fn(|row| (0..4).map(|k| a[k][row] * b[col][k]).sum()))
}

/// `M·[p 1]ᵀ` (affine part) of a column-major matrix.
fn transform(m: &Matrix, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|row| m[0][row] * p[0] + m[1][row] * p[1] + m[2][row] * p[2] + m[3][row])
}

/// Determinant of the upper-left 3 × 3 block (the linear part).
fn determinant3(m: &Matrix) -> f64 {
    let c = |col: usize, row: usize| m[col][row];
    c(0, 0) * (c(1, 1) * c(2, 2) - c(2, 1) * c(1, 2)) - c(1, 0) * (c(0, 1) * c(2, 2) - c(2, 1) * c(0, 2))
        + c(2, 0) * (c(0, 1) * c(1, 2) - c(1, 1) * c(0, 2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_become_counter_clockwise_triangles() {
        assert_eq!(triangles(Mode::TriangleStrip, &[0, 1, 2, 3]), vec![[0, 1, 2], [2, 1, 3]]);
        assert_eq!(triangles(Mode::TriangleFan, &[0, 1, 2, 3]), vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(triangles(Mode::Triangles, &[0, 1, 2, 3]), vec![[0, 1, 2]]);
    }

    #[test]
    fn matrices_compose_parent_first_and_mirroring_is_seen() {
        let mut shift: Matrix = std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j))));
        shift[3] = [1.0, 2.0, 3.0, 1.0];
        let mut double = shift;
        double[3] = [0.0, 0.0, 0.0, 1.0];
        double[0][0] = 2.0;
        double[1][1] = 2.0;
        double[2][2] = -2.0;
        // Parent shifts, child scales: the point is scaled, then shifted.
        let world = multiply(&shift, &double);
        assert_eq!(transform(&world, [1.0, 1.0, 1.0]), [3.0, 4.0, 1.0]);
        assert!(determinant3(&world) < 0.0 && determinant3(&shift) > 0.0);
    }

    /// The buffers of a document whose one buffer has `uri` and declares
    /// `length` bytes, its files looked up in `dir`.
    fn buffers_of(uri: &str, length: u64, dir: &Path) -> Result<Vec<Vec<u8>>, TetraError> {
        let document = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"uri": uri, "byteLength": length}]
        });
        let bytes = document.to_string().into_bytes();
        gltf_buffers(&gltf::Gltf::from_slice(&bytes).unwrap(), Some(dir), &bytes)
    }

    /// The message of a refusal.
    fn refusal(result: Result<Vec<Vec<u8>>, TetraError>) -> String {
        match result {
            Err(TetraError::Parse { format: "glTF", message }) => message,
            other => panic!("expected a glTF error, got {other:?}"),
        }
    }

    const TWELVE: &[u8; 12] = b"0123456789ab";

    #[test]
    fn percent_encoded_buffer_paths_are_decoded() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("bar data.bin"), TWELVE).unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        assert_eq!(buffers_of("bar%20data.bin", 12, dir.path()).unwrap(), [TWELVE]);
        assert_eq!(buffers_of("../bar%20data.bin", 12, &dir.path().join("sub")).unwrap(), [TWELVE]);
    }

    #[test]
    fn data_uri_buffers_are_decoded() {
        let dir = tempfile::tempdir().unwrap();
        for media in ["application/octet-stream", "application/gltf-buffer"] {
            let uri = format!("data:{media};base64,MDEyMzQ1Njc4OWFi");
            assert_eq!(buffers_of(&uri, 12, dir.path()).unwrap(), [TWELVE], "{media}");
        }
        let message = refusal(buffers_of("data:application/octet-stream;base64,MDEy", 12, dir.path()));
        assert!(message.contains("holds 3 bytes, 12 declared"), "{message}");
    }

    #[test]
    fn a_longer_buffer_file_is_read_to_its_declared_length() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.bin"), TWELVE).unwrap();
        assert_eq!(buffers_of("a.bin", 5, dir.path()).unwrap(), [&TWELVE[..5]]);
    }

    #[test]
    fn a_shorter_buffer_file_is_refused_before_its_declared_length_is_allocated() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.bin");
        std::fs::write(&file, TWELVE).unwrap();
        for declared in [13, 1_000_000_000_000_000] {
            let message = refusal(buffers_of("a.bin", declared, dir.path()));
            let expected =
                format!("buffer 0: file {} has 12 bytes, the glTF declares {declared}", file.display());
            assert_eq!(message, expected);
        }
    }

    #[test]
    fn a_directory_is_refused_as_a_buffer() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let message = refusal(buffers_of("sub", 12, dir.path()));
        assert!(message.starts_with("buffer 0: ") && message.ends_with("sub is a directory"), "{message}");
    }

    /// `/dev/zero` would be read until memory runs out and a FIFO waited on
    /// for a writer: both are refused before they are opened.
    #[cfg(target_os = "linux")]
    #[test]
    fn devices_and_fifos_are_refused_without_reading_them() {
        let dir = tempfile::tempdir().unwrap();
        let message = refusal(buffers_of("/dev/zero", 12, dir.path()));
        assert!(message.contains("'/dev/zero' is an absolute path"), "{message}");
        std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.bin")).unwrap();
        let made = std::process::Command::new("mkfifo").arg(dir.path().join("fifo.bin")).status().unwrap();
        assert!(made.success());
        for name in ["zero.bin", "fifo.bin"] {
            let message = refusal(buffers_of(name, 12, dir.path()));
            assert!(message.ends_with(&format!("{name} is not a regular file")), "{message}");
        }
    }
}
