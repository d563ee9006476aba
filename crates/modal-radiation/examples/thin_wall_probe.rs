//! What a thin wall does to the radiation solve, measured three ways
//! (docs/radiation.md, "Thin walls"; BENCHMARKS.md, "The thin disc as a
//! screen").
//!
//! - `disc FREQ_HZ THICKNESS_M RINGS [ORDER]`: a disc of radius 0.1 m whose
//!   faces move broadside with `(r/a)^ORDER cos(ORDER φ)` (0: rigid
//!   translation, the default), as an open screen of no thickness
//!   ([`modal_radiation::screen`]) and as the closed disc THICKNESS_M thick by
//!   the production collocation (Burton–Miller and the conventional
//!   equation), by Burton–Miller with a continuous pressure in its
//!   hypersingular term ([`modal_radiation::continuous`], a study) and by
//!   the screen's Galerkin scheme on the closed surface
//!   (whose jump's double layer is then the exterior field): `|p|` at
//!   0.4 m from the centre, 0, 0.6 and 1.2 rad from the axis, in the plane
//!   `φ = 0`. `tools/screen_ref.py` solves the same meshes with bempp-cl.
//! - `bank BANK MODE[,MODE…] [--point X,Y,Z …]`: a bank whose surface is one
//!   thin wall (a free plate) solved as its mid-surface screen, with
//!   `modal radiation --json`'s fields (for `tools/rad_ref.py --compare`).
//! - `walls BANK`: the thin-wall check of `modal radiation` and its time.
//!
//! `cargo run --release -p modal-radiation --example thin_wall_probe -- disc 2000 0.008 16`
use modal_bank::ModeBank;
use modal_radiation::modes::{boundary_mesh, corner_mesh, normal_velocity};
use modal_radiation::multipole::fit;
use modal_radiation::screen::solve_screen;
use modal_radiation::walls::{opposite_panels, thin_walls};
use modal_radiation::{c64, solve, Adjacency, Air, BoundaryMesh, Formulation, SurfaceField};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let run = match args.first().map(String::as_str) {
        Some("disc") if args.len() >= 4 => disc(&args[1..]),
        Some("bank") if args.len() >= 3 => bank(&args[1..]),
        Some("walls") if args.len() == 2 => walls(&args[1]),
        _ => Err("usage: thin_wall_probe disc FREQ_HZ THICKNESS_M RINGS [ORDER] | bank BANK MODES [--point X,Y,Z …] | walls BANK".into()),
    };
    if let Err(e) = run {
        eprintln!("thin_wall_probe: {e}");
        std::process::exit(1);
    }
}

type Failure = Box<dyn std::error::Error>;
type Probe = Result<(), Failure>;

/// A wall's mid-surface and, per panel of it, `(its panel, the panel across the wall)`.
type MidSurface = (BoundaryMesh, Vec<(usize, usize)>);

fn disc(args: &[String]) -> Probe {
    let (f, t, rings): (f64, f64, usize) = (args[0].parse()?, args[1].parse()?, args[2].parse()?);
    let order: i32 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let a = 0.1;
    let air = Air::default();
    let k = std::f64::consts::TAU * f / air.sound_speed_m_s;
    let pattern = |c: [f64; 3]| {
        let r = (c[0] * c[0] + c[1] * c[1]).sqrt() / a;
        r.powi(order) * (order as f64 * c[1].atan2(c[0])).cos()
    };
    let points: Vec<[f64; 3]> =
        [0.0f64, 0.6, 1.2].iter().map(|th| [0.4 * th.sin(), 0.0, 0.4 * th.cos()]).collect();
    let levels = |field: &SurfaceField, mesh: &BoundaryMesh| -> Result<String, Failure> {
        let p = field.pressures_at(mesh, &points)?;
        Ok(p.iter().map(|z| format!("{:.4e}", z.norm())).collect::<Vec<_>>().join("  "))
    };
    let (v, tris) = modal_mesh::disc_surface(a, 0.0, rings);
    let screen = BoundaryMesh::new(v, &tris)?;
    let vs: Vec<c64> = screen.panels.iter().map(|p| c64::new(pattern(p.centroid), 0.0)).collect();
    let jump = solve_screen(&screen, air, f, &[vs])?;
    println!(
        "screen (P1 Galerkin)          {}",
        levels(&jump_field(&jump.panel_mean[0], f, k, air), &screen)?
    );
    let (v, tris) = modal_mesh::disc_surface(a, t, rings);
    let closed = BoundaryMesh::new(v, &tris)?;
    let vc: Vec<c64> =
        closed.panels.iter().map(|p| c64::new(p.normal[2].round() * pattern(p.centroid), 0.0)).collect();
    for (name, form) in
        [("Burton–Miller", Formulation::BurtonMiller), ("conventional", Formulation::Conventional)]
    {
        let s = solve(&closed, air, f, std::slice::from_ref(&vc), form)?.remove(0);
        println!("closed, {name:<14} (P0)   {}", levels(&s, &closed)?);
    }
    let s =
        modal_radiation::continuous::solve_continuous(&closed, air, f, std::slice::from_ref(&vc))?.remove(0);
    println!("closed, BM, continuous N     {}", levels(&s, &closed)?);
    let jump = solve_screen(&closed, air, f, &[vc])?;
    println!(
        "closed, jump (P1 Galerkin)    {}",
        levels(&jump_field(&jump.panel_mean[0], f, k, air), &closed)?
    );
    Ok(())
}

/// The field whose representation is the double layer of `jump` (no
/// single layer: the velocity is left out).
fn jump_field(jump: &[c64], f: f64, k: f64, air: Air) -> SurfaceField {
    SurfaceField {
        frequency_hz: f,
        wavenumber: k,
        air,
        pressure: jump.to_vec(),
        normal_velocity: vec![c64::new(0.0, 0.0); jump.len()],
    }
}

fn bank(args: &[String]) -> Probe {
    let bank = ModeBank::load(std::path::Path::new(&args[0]))?;
    let modes: Vec<usize> = args[1].split(',').map(|s| s.trim().parse()).collect::<Result<_, _>>()?;
    let points: Vec<[f64; 3]> = args[2..]
        .chunks(2)
        .map(|c| -> Result<[f64; 3], Failure> {
            let v: Vec<f64> = c
                .get(1)
                .ok_or("--point needs X,Y,Z")?
                .split(',')
                .map(|s| s.parse())
                .collect::<Result<_, _>>()?;
            Ok([v[0], v[1], v[2]])
        })
        .collect::<Result<_, _>>()?;
    let fine = boundary_mesh(&bank)?;
    let mesh = corner_mesh(&bank)?.ok_or("a quadratic bank is expected")?;
    let (screen, faces) = mid_surface(&mesh)?;
    eprintln!("screen: {} of {} corner panels", screen.len(), mesh.len());
    let air = Air::default();
    let centre = bank.mass.center_of_mass_m;
    let mut out = Vec::new();
    for &m in &modes {
        // Corner-panel velocity: the area-weighted mean over its four split panels.
        let vf = normal_velocity(&bank, &fine, m)?;
        let v: Vec<c64> = (0..mesh.len())
            .map(|t| {
                let area: f64 = (0..4).map(|j| fine.panels[4 * t + j].area).sum();
                (0..4).map(|j| vf[4 * t + j] * fine.panels[4 * t + j].area).sum::<c64>() / area
            })
            .collect();
        let vs: Vec<c64> = faces.iter().map(|&(j, o)| (v[j] - v[o]) * 0.5).collect();
        let f = bank.frequencies_hz[m];
        let k = std::f64::consts::TAU * f / air.sound_speed_m_s;
        let time = std::time::Instant::now();
        let jump = solve_screen(&screen, air, f, &[vs])?;
        let multipole = fit(&screen, &[jump_field(&jump.panel_mean[0], f, k, air)], centre, 1e-4).remove(0);
        let power = multipole.radiated_power(air);
        eprintln!("mode {m} at {f:.1} Hz: {:.1} s, {power:.4e} W", time.elapsed().as_secs_f64());
        let p: Vec<String> = points
            .iter()
            .map(|&x| multipole.pressure_at(x))
            .map(|z| format!("[{:e}, {:e}]", z.re, z.im))
            .collect();
        out.push(format!(
            "{{\"index\": {m}, \"frequency_hz\": {f}, \"radiated_power_w\": {power:e}, \"pressure_pa\": [{}]}}",
            p.join(", ")
        ));
    }
    println!("{{\"modes\": [{}]}}", out.join(", "));
    Ok(())
}

/// One face of a wall whose every panel but its rim has the other face
/// under it, moved to the mid-surface, and per screen panel `(its panel,
/// the panel across the wall)`: the face is the component (over edges
/// turning < 25°) of panels with a wall under them that pairs with a
/// higher-numbered component.
fn mid_surface(mesh: &BoundaryMesh) -> Result<MidSurface, Failure> {
    let opposite = opposite_panels(mesh, 1.5);
    let adjacency = Adjacency::new(mesh);
    let cos_max = modal_radiation::cluster::MAX_NORMAL_ANGLE_DEG.to_radians().cos();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let n = mesh.len();
    let mut component = vec![usize::MAX; n];
    let mut count = 0;
    for seed in 0..n {
        if component[seed] != usize::MAX || opposite[seed].is_none() {
            continue;
        }
        let mut stack = vec![seed];
        component[seed] = count;
        while let Some(p) = stack.pop() {
            for &q in adjacency.neighbours(p) {
                let smooth = dot(mesh.panels[p].normal, mesh.panels[q].normal) >= cos_max;
                if component[q] == usize::MAX && opposite[q].is_some() && smooth {
                    component[q] = count;
                    stack.push(q);
                }
            }
        }
        count += 1;
    }
    let mut votes = vec![std::collections::BTreeMap::<usize, f64>::new(); count];
    for (j, o) in opposite.iter().enumerate() {
        if let Some(o) = *o {
            *votes[component[j]].entry(component[o]).or_default() += mesh.panels[j].area;
        }
    }
    let partner: Vec<Option<usize>> =
        votes.iter().map(|v| v.iter().max_by(|a, b| a.1.total_cmp(b.1)).map(|(&c, _)| c)).collect();
    let faces: Vec<(usize, usize)> = (0..n)
        .filter(|&j| component[j] != usize::MAX && partner[component[j]].is_some_and(|p| p > component[j]))
        .filter_map(|j| opposite[j].map(|o| (j, o)))
        .collect();
    if faces.is_empty() {
        return Err("no thin wall".into());
    }
    // Each vertex moves by the mean over its face panels of −(t/2) n.
    let mut shift = vec![([0.0f64; 3], 0usize); mesh.vertices.len()];
    for &(j, o) in &faces {
        let (p, q) = (&mesh.panels[j], &mesh.panels[o]);
        let t = dot(p.normal, [0, 1, 2].map(|c| p.centroid[c] - q.centroid[c]));
        for &c in &p.corners {
            (0..3).for_each(|d| shift[c].0[d] -= 0.5 * t * p.normal[d]);
            shift[c].1 += 1;
        }
    }
    let vertices = mesh
        .vertices
        .iter()
        .zip(&shift)
        .map(|(x, (s, k))| if *k > 0 { [0, 1, 2].map(|d| x[d] + s[d] / *k as f64) } else { *x })
        .collect();
    let triangles: Vec<[usize; 3]> = faces.iter().map(|&(j, _)| mesh.panels[j].corners).collect();
    Ok((BoundaryMesh::new(vertices, &triangles)?, faces))
}

fn walls(path: &str) -> Probe {
    let bank = ModeBank::load(std::path::Path::new(path))?;
    let mesh = corner_mesh(&bank)?.map_or_else(|| boundary_mesh(&bank), Ok)?;
    let time = std::time::Instant::now();
    let walls = thin_walls(&mesh);
    println!("{} panels: {walls:?} in {:.3} s", mesh.len(), time.elapsed().as_secs_f64());
    Ok(())
}
