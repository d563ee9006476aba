//! `modal mesh …`: generate a tet mesh, or tetrahedralize a surface mesh.

use anyhow::{Context, Result};
use modal_mesh::generate::{ElementSizes, Shape};
use modal_mesh::TetMesh;

use super::args::{GenerateArgs, MeshShape};
use super::output::{print_json, warn};

pub fn run(shape: MeshShape) -> Result<()> {
    match shape {
        MeshShape::Box { size, common } => generate(Shape::Box { size }, common),
        MeshShape::Cylinder { radius, length, common } => {
            generate(Shape::Cylinder { radius, length }, common)
        }
        MeshShape::Tube { inner_radius, outer_radius, length, common } => {
            generate(Shape::Tube { inner_radius, outer_radius, length }, common)
        }
        MeshShape::Sphere { radius, common } => generate(Shape::Sphere { radius }, common),
        MeshShape::Bowl { radius, thickness, common } => generate(Shape::Bowl { radius, thickness }, common),
        MeshShape::Corpus(args) => super::corpus::run(args),
        MeshShape::Tet { input, out, cell, scale, part, sheet_thickness, modes, json } => {
            super::check_not_input(&out, &input, "-o")?;
            let (surface, mut report) = modal_tetra::read_surface(&input, scale, part.as_deref())
                .with_context(|| format!("cannot read surface mesh {}", input.display()))?;
            super::prepare_output(&out).with_context(|| format!("cannot write {}", out.display()))?;
            if sheet_thickness.is_some() {
                report.drop_open_warning();
            }
            report.warnings.iter().for_each(|w| warn(w));
            let options = modal_tetra::TetOptions {
                cell,
                sheet_thickness,
                resolved_modes: modes,
                ..Default::default()
            };
            let (mesh, tet_report) = modal_tetra::tetrahedralize(&surface, &options)
                .with_context(|| format!("cannot tetrahedralize {}", input.display()))?;
            write_mesh(&out, &mesh)?;
            tet_report.warnings.iter().for_each(|w| warn(w));
            let r = &tet_report;
            let summary = serde_json::json!({
                "out": out.display().to_string(),
                "input_triangles": report.triangles,
                "cavities": report.cavities,
                "tets": r.tets,
                "nodes": r.nodes,
                "cell_m": r.cell_m,
                "min_dihedral_deg": r.min_dihedral_deg,
                "max_dihedral_deg": r.max_dihedral_deg,
                "volume_m3": r.volume_m3,
                "surface_volume_m3": r.surface_volume_m3,
                "max_surface_deviation_m": r.max_surface_deviation_m,
                "hinged_tets_dropped": r.hinged_tets_dropped,
                "order": mesh.order(),
                "curved_edges": r.curved_edges,
                "min_cell_m": r.min_cell_m,
                "thin_samples": r.thin_samples,
                "min_thickness_m": r.min_thickness_m,
                "max_surface_gap_m": r.max_surface_gap_m,
                "wall_layers": r.wall_layers,
                "sheets_thickened": r.sheets_thickened,
            });
            if json {
                print_json(&summary)
            } else {
                println!(
                    "{} triangles -> {} tets, {} nodes (cell {:.4} m); dihedral angles {:.1}..{:.1} deg; \
                     volume {:.6e} m^3 vs enclosed {:.6e} m^3; max surface deviation {:.3e} m",
                    report.triangles,
                    r.tets,
                    r.nodes,
                    r.cell_m,
                    r.min_dihedral_deg,
                    r.max_dihedral_deg,
                    r.volume_m3,
                    r.surface_volume_m3,
                    r.max_surface_deviation_m
                );
                if r.sheets_thickened > 0 {
                    println!(
                        "sheets: {} open part(s) given a {:.3e} m wall",
                        r.sheets_thickened,
                        sheet_thickness.unwrap_or(f64::NAN)
                    );
                }
                if report.cavities > 0 {
                    println!("hollow: {} inner wall(s) facing inward bound cavities", report.cavities);
                }
                if r.wall_layers > 0 {
                    println!(
                        "thin shell: {} layer(s) of tets across its {:.3e} m wall, edges along it up to {:.3e} m",
                        r.wall_layers,
                        r.min_thickness_m.unwrap_or(f64::NAN),
                        r.cell_m
                    );
                }
                println!("wrote {}", out.display());
                Ok(())
            }
        }
    }
}

fn generate(shape: Shape, args: GenerateArgs) -> Result<()> {
    let sizes = args.h.map_or_else(|| shape.default_sizes(args.order), ElementSizes::uniform);
    let h = sizes.h;
    let mesh = modal_mesh::generate::generate_sized(&shape, sizes, args.order)?;
    super::prepare_output(&args.out).with_context(|| format!("cannot write {}", args.out.display()))?;
    write_mesh(&args.out, &mesh)?;
    let summary = serde_json::json!({
        "out": args.out.display().to_string(),
        "nodes": mesh.nodes.len(),
        "tets": mesh.cells.len(),
        "order": mesh.order(),
        "element_size_m": h,
        "axial_element_size_m": sizes.axial,
    });
    if args.json {
        print_json(&summary)
    } else {
        // Four decimals of a metre for ordinary sizes, three digits otherwise.
        let h = if (1e-3..1e3).contains(&h) { format!("{h:.4}") } else { format!("{h:.3e}") };
        println!(
            "wrote {} ({} nodes, {} tets, order {}, element size {h} m)",
            args.out.display(),
            mesh.nodes.len(),
            mesh.cells.len(),
            mesh.order(),
        );
        Ok(())
    }
}

fn write_mesh(path: &std::path::Path, mesh: &TetMesh) -> Result<()> {
    super::write_buffered(path, |file| modal_mesh::write_msh41(mesh, file))
}
