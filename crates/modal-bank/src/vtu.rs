//! ParaView export: the bank's surface as a VTK XML UnstructuredGrid (`.vtu`,
//! ASCII) with every mode shape as 3-component point data.
//!
//! Cells are linear triangles (VTK type 5) or, for banks with mid-edge nodes
//! (TET10), quadratic triangles (VTK type 22: corners 0, 1, 2 then the
//! mid-edge nodes of edges (0,1), (1,2), (2,0)). Point arrays:
//! `mode_000_<f>Hz`, `mode_001_<f>Hz`, … (mass-normalized shapes, 1/√kg,
//! `<f>` the undamped frequency with two decimals) and `node_id`; field data
//! `frequencies_hz`. In ParaView, colour by a mode array and apply
//! "Warp By Vector" to see it move.

use crate::fsio::atomic_write;
use crate::{BankError, ModeBank};
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// VTK cell type of a linear triangle.
const VTK_TRIANGLE: u8 = 5;
/// VTK cell type of a quadratic (6-node) triangle.
const VTK_QUADRATIC_TRIANGLE: u8 = 22;

/// Name of the point-data array of mode `i`, e.g. `mode_003_1234.57Hz`.
pub fn mode_array_name(bank: &ModeBank, i: usize) -> String {
    format!("mode_{i:03}_{:.2}Hz", bank.frequencies_hz[i])
}

/// Writes the bank as a `.vtu` document to `out` (validates first).
pub fn export_vtu(bank: &ModeBank, out: impl Write) -> Result<(), BankError> {
    bank.validate()?;
    let mut w = BufWriter::new(out);
    write_vtu(bank, &mut w).and_then(|()| w.flush()).map_err(BankError::Export)
}

/// Writes the `.vtu` file `path` atomically (nothing is left on error).
pub fn export_vtu_file(bank: &ModeBank, path: impl AsRef<Path>) -> Result<(), BankError> {
    bank.validate()?;
    atomic_write(path.as_ref(), |w| write_vtu(bank, w))
}

/// The cell connectivity: per triangle 3 or 6 surface-node indices.
fn cells(bank: &ModeBank) -> (Vec<Vec<usize>>, u8) {
    let tris = &bank.surface.triangles;
    match &bank.surface.triangle_edge_nodes {
        Some(edges) => (
            tris.iter().zip(edges).map(|(t, e)| vec![t[0], t[1], t[2], e[0], e[1], e[2]]).collect(),
            VTK_QUADRATIC_TRIANGLE,
        ),
        None => (tris.iter().map(|t| t.to_vec()).collect(), VTK_TRIANGLE),
    }
}

fn data_array<T: std::fmt::Display>(
    w: &mut dyn Write,
    attrs: &str,
    values: impl IntoIterator<Item = T>,
    per_line: usize,
) -> io::Result<()> {
    writeln!(w, "        <DataArray {attrs} format=\"ascii\">")?;
    let mut count = 0;
    for v in values {
        write!(w, "{}{v}", if count % per_line == 0 { "          " } else { " " })?;
        count += 1;
        if count % per_line == 0 {
            writeln!(w)?;
        }
    }
    if count % per_line != 0 {
        writeln!(w)?;
    }
    writeln!(w, "        </DataArray>")
}

fn write_vtu(bank: &ModeBank, w: &mut dyn Write) -> io::Result<()> {
    let s = bank.surface_node_count();
    let (cells, cell_type) = cells(bank);
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(w, "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">")?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(w, "    <FieldData>")?;
    let n = bank.mode_count();
    data_array(
        w,
        &format!("type=\"Float64\" Name=\"frequencies_hz\" NumberOfTuples=\"{n}\""),
        &bank.frequencies_hz,
        6,
    )?;
    writeln!(w, "    </FieldData>")?;
    writeln!(w, "    <Piece NumberOfPoints=\"{s}\" NumberOfCells=\"{}\">", cells.len())?;
    let active = if n > 0 { format!(" Vectors=\"{}\"", mode_array_name(bank, 0)) } else { String::new() };
    writeln!(w, "      <PointData{active}>")?;
    for i in 0..n {
        let name = mode_array_name(bank, i);
        let shape = &bank.shapes[i * s * 3..(i + 1) * s * 3];
        data_array(w, &format!("type=\"Float32\" Name=\"{name}\" NumberOfComponents=\"3\""), shape, 3)?;
    }
    data_array(w, "type=\"Int64\" Name=\"node_id\"", &bank.surface.node_ids, 8)?;
    writeln!(w, "      </PointData>")?;
    writeln!(w, "      <Points>")?;
    let points = bank.surface.positions.iter().flatten();
    data_array(w, "type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"", points, 3)?;
    writeln!(w, "      </Points>")?;
    writeln!(w, "      <Cells>")?;
    data_array(
        w,
        "type=\"Int64\" Name=\"connectivity\"",
        cells.iter().flatten(),
        cells.first().map_or(3, Vec::len),
    )?;
    let offsets = cells.iter().scan(0, |end, c| {
        *end += c.len();
        Some(*end)
    });
    data_array(w, "type=\"Int64\" Name=\"offsets\"", offsets, 8)?;
    data_array(w, "type=\"UInt8\" Name=\"types\"", cells.iter().map(|_| cell_type), 16)?;
    writeln!(w, "      </Cells>")?;
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}
