//! The cache key: a hash of every input that changes the result.

use std::path::Path;

use modal_bank::CacheKey;

use crate::{MeshSource, PrecomputeError, Request, SOLVER_VERSION};

/// Hex digest identifying the result of `request`: mesh bytes (both files of
/// a TetGen pair), scale, material incl. α and β, order, band, mode cap,
/// clamping box, surface-meshing options, the accuracy target (surface meshes) and the
/// solver version.
pub fn cache_key(request: &Request) -> Result<String, PrecomputeError> {
    let mut key = CacheKey::new(SOLVER_VERSION);
    match &request.source {
        MeshSource::File(path) => {
            for file in companion_files(path) {
                let bytes = std::fs::read(&file)
                    .map_err(|source| PrecomputeError::Io { path: file.display().to_string(), source })?;
                let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
                key = key.add_str("mesh_kind", &ext).add("mesh", &bytes);
            }
            if modal_tetra::SurfaceFormat::from_path(path) == Some(modal_tetra::SurfaceFormat::Gltf) {
                // A .gltf's geometry lives in the files its buffers name (a .glb's
                // own chunk is in the bytes above): a re-exported .bin is a new mesh.
                for (i, bytes) in modal_tetra::gltf_uri_buffers(path)?.iter().enumerate() {
                    key = key.add_u64("gltf_uri_buffer", i as u64).add("mesh", bytes);
                }
            }
        }
        MeshSource::Memory { identity, .. } => key = key.add_str("mesh_identity", identity),
    }
    let m = &request.material;
    key = key
        .add_f64("scale", request.scale)
        .add_f64("youngs_pa", m.youngs_pa)
        .add_f64("poisson", m.poisson)
        .add_f64("density_kg_m3", m.density_kg_m3)
        .add_f64("alpha", m.alpha)
        .add_f64("beta", m.beta)
        .add_u64("order", request.order as u64)
        .add_f64("min_freq_hz", request.min_freq_hz)
        .add_f64("max_freq_hz", request.max_freq_hz)
        .add_u64("max_modes", request.max_modes as u64)
        .add_str("fix_box", &format!("{:?}", request.fix_box))
        .add_str("mesher", &request.surface_meshing().tet_options().cache_key_fields())
        .add_str("part", &format!("{:?}", request.surface.part));
    // The accuracy target chooses the discretization of a surface mesh (and adds the
    // estimate); a prescribed tet mesh is solved as it is. Absent: the key is unchanged.
    if let (Some(a), true) = (&request.accuracy, crate::levels::remeshable(&request.source)) {
        key = key
            .add_str("accuracy", &format!("{}:{}:{}", crate::levels::LEVELS_VERSION, a.target_pct, a.modes));
    }
    Ok(key.finish())
}

/// The files whose bytes define a mesh: a TetGen mesh is two files.
fn companion_files(path: &Path) -> Vec<std::path::PathBuf> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    match ext {
        "node" | "ele" => vec![path.with_extension("node"), path.with_extension("ele")],
        _ => vec![path.to_path_buf()],
    }
}
