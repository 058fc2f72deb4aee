//! The `mc` model over (η, g) (`McGridSet`) against independent data: how large its
//! interpolation errors are (BENCHMARKS.md, "The `mc` model over g").
//!
//! ```text
//! cargo run -p scatterfit-mc --example g_model_check -- mcml [MAX_G_STEP]
//! cargo run -p scatterfit-mc --example g_model_check -- eta-loo
//! cargo run -p scatterfit-mc --example g_model_check -- eta-coarse
//! cargo run -p scatterfit-mc --example g_model_check -- table TABLE.json [MAX_G_STEP]
//! cargo run --release -p scatterfit-mc --example g_model_check -- cost
//! ```
//! * `mcml`: the shipped grid (or with `MAX_G_STEP` = 1, interpolating across the gap from g = 0 to
//!   0.8) against MCML's profiles and totals (`data/reference/mcml_profiles_g.csv`, σ′t = 1 mm⁻¹):
//!   the reflected fraction per radial window (reduced radii 0–0.5–1–2–5–10–19.75) and the total.
//!   MCML's standard error per window is estimated as a short engine run's (4 000 photons, seed 99:
//!   both codes score the same estimator) × √(4 000/N_MCML). At g = 0.5 also the g = 0 and the
//!   g = 0.8 tables used as they are (what the nearest node would give).
//! * `eta-loo`: leave-one-out in η on the shipped g = 0.9 set (0.1 apart at η 1.0–1.7): each
//!   interior table of 1.1–1.6 against the set without it, and the 0.2-spaced subset's prediction at
//!   1.1, 1.3, 1.5 (what the g = 0.8 set, 0.2 apart, does between its tables): RMS relative
//!   difference of Rd(r) over reduced-radius windows per α′, and of the total.
//! * `eta-coarse`: the η layout of the sparse g nodes (0.95, and the 0.5 / 0.7 sets), η 1.0, 1.4,
//!   1.8, 2.4 (with and without 1.05, 1.1, 1.2 added), taken from the shipped g = 0.8 and 0.9 sets,
//!   against those sets' own tables at the η left out (1.2, 1.6, 2.0, 2.2): what Catmull-Rom over
//!   0.4–0.6 in η costs.
//! * `table`: the grid interpolated to the g and η of a table file (e.g. a 10⁵-photon study table at
//!   g = 0.85 or 0.7, η = 1.4), against that table, by α′ and window.
//! * `cost`: parsing the shipped grid, and one `eval` (the fit's hot path: model + 300 radii) at
//!   g = 0, at a node g = 0.9 and between nodes (g = 0.85).

use scatterfit_mc::grid_g::albedo_from_reduced;
use scatterfit_mc::model::{McProfile, McTable, McTableSet};
use scatterfit_mc::{Beam, Layer, McGridSet, RadialGrid, Sample, Simulation, bundled};
use scatterfit_optics::{ModelFamily, OpticalProperties, ProfileModel};

const ALBEDOS: [f64; 8] = [0.3, 0.5, 0.7, 0.9, 0.97, 0.99, 0.999, 0.9999];
const WINDOWS: [(f64, f64); 4] = [(0.3, 1.0), (1.0, 3.0), (3.0, 10.0), (10.0, 20.0)];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("mcml") => mcml(args.get(1).map(|s| s.parse().expect("MAX_G_STEP"))),
        Some("eta-loo") => eta_loo(),
        Some("eta-coarse") => eta_coarse(),
        Some("cost") => cost(),
        Some("table") => table(
            &args[1],
            args.get(2).map(|s| s.parse().expect("MAX_G_STEP")),
        ),
        _ => {
            eprintln!("usage: g_model_check mcml [MAX_G_STEP] | eta-loo | table FILE [MAX_G_STEP]")
        }
    }
}

fn grid(max_step: Option<f64>) -> McGridSet {
    let g = McGridSet::bundled().expect("bundled grid");
    // `G_EXTRA_DIR=DIR`: tables in DIR (`build_g_tables --out DIR`) join the grid as nodes at g
    // the shipped grid does not hold (a set per g; only their η answer) — to measure a node set
    // before it ships.
    let mut nodes = g.nodes().to_vec();
    if let Ok(dir) = std::env::var("G_EXTRA_DIR") {
        let mut extra: Vec<McTable> = std::fs::read_dir(&dir)
            .expect("G_EXTRA_DIR")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .map(|p| McTable::load(&p).expect("table"))
            .filter(|t| !g.g_nodes().iter().any(|&n| (n - t.spec().g).abs() < 1e-9))
            .collect();
        extra.sort_by(|a, b| {
            (a.spec().g, a.spec().eta)
                .partial_cmp(&(b.spec().g, b.spec().eta))
                .expect("finite")
        });
        let mut gs: Vec<f64> = extra.iter().map(|t| t.spec().g).collect();
        gs.dedup();
        for gv in gs {
            let set: Vec<McTable> = extra.iter().filter(|t| t.spec().g == gv).cloned().collect();
            eprintln!("extra node g = {gv}: {} tables", set.len());
            nodes.push(McTableSet::new(set).expect("set"));
        }
    }
    McGridSet::new(nodes, max_step.unwrap_or(g.max_step())).expect("grid")
}

/// ∫ 2πr Rd(r) dr over [lo, hi] (Simpson in ln r, 400 steps).
fn window(m: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let lo = lo.max(1e-4);
    let n = 400;
    let (u0, u1) = (lo.ln(), hi.ln());
    let h = (u1 - u0) / n as f64;
    let f = |u: f64| {
        let r = u.exp();
        2.0 * std::f64::consts::PI * r * r * m(r)
    };
    let mut s = f(u0) + f(u1);
    for k in 1..n {
        s += f(u0 + h * k as f64) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

struct McmlCase {
    g: f64,
    eta: f64,
    ap: f64,
    photons: f64,
    total: f64,
    windows: Vec<f64>,
}

const MCML_WINDOWS: [f64; 7] = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 19.75];

fn mcml_cases() -> Vec<McmlCase> {
    let text = include_str!("../../../data/reference/mcml_profiles_g.csv");
    let mut cases: Vec<McmlCase> = Vec::new();
    for line in text.lines() {
        if line.starts_with('#') || line.starts_with('g') {
            continue;
        }
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let (g, eta, ap) = (v[0], v[1], v[2]);
        if !cases
            .last()
            .is_some_and(|c| (c.g, c.eta, c.ap) == (g, eta, ap))
        {
            cases.push(McmlCase {
                g,
                eta,
                ap,
                photons: v[3],
                total: v[4],
                windows: vec![0.0; MCML_WINDOWS.len() - 1],
            });
        }
        let c = cases.last_mut().unwrap();
        let (lo, hi, rd) = (v[6], v[7], v[8]);
        let area = std::f64::consts::PI * (hi * hi - lo * lo);
        if let Some(k) = (0..MCML_WINDOWS.len() - 1)
            .find(|&k| lo >= MCML_WINDOWS[k] - 1e-9 && hi <= MCML_WINDOWS[k + 1] + 1e-9)
        {
            c.windows[k] += rd * area;
        }
    }
    cases
}

/// MCML's standard error per window and of the total, from a short engine run.
fn mcml_stderr(c: &McmlCase) -> (Vec<f64>, f64) {
    let layer = Layer::new(1.0 - c.ap, c.ap / (1.0 - c.g), c.g, c.eta, f64::INFINITY).unwrap();
    let sample = Sample::new(vec![layer], 1.0, 1.0).unwrap();
    let n = 4_000;
    let r = Simulation::new(
        sample,
        Beam::pencil(),
        RadialGrid::from_edges(MCML_WINDOWS.to_vec()).unwrap(),
        n,
        99,
    )
    .unwrap()
    .run();
    let scale = (n as f64 / c.photons).sqrt();
    let w = (0..MCML_WINDOWS.len() - 1)
        .map(|k| r.rd_profile[k].stderr * r.grid.area(k) * scale)
        .collect();
    (w, r.rd_total.stderr * scale)
}

fn mcml(max_step: Option<f64>) {
    let grid = grid(max_step);
    println!("grid: {}", grid.coverage());
    println!(
        "| g | η | α′ | model | total − MCML (z) | window [0,0.5) | [0.5,1) | [1,2) | [2,5) | [5,10) | [10,19.75) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut z_all = Vec::new();
    for c in mcml_cases() {
        let (se_w, se_t) = mcml_stderr(&c);
        let props = OpticalProperties::new(c.ap, 1.0 - c.ap, c.eta)
            .unwrap()
            .with_g(c.g)
            .unwrap();
        let mut models: Vec<(String, Box<dyn ProfileModel>)> = Vec::new();
        match ModelFamily::profile(&grid, &props) {
            Ok(m) => models.push(("grid".into(), m)),
            Err(e) => println!("| {} | {} | {} | grid | refused: {e} |", c.g, c.eta, c.ap),
        }
        if c.g == 0.5 {
            for node in &grid.nodes()[..2] {
                if let Ok(m) = McProfile::new(node, &props) {
                    models.push((format!("g = {} tables", node.g()), Box::new(m)));
                }
            }
        }
        for (name, m) in models {
            let mut cells = Vec::new();
            for k in 0..MCML_WINDOWS.len() - 1 {
                let ours = window(&|r| m.rd(r), MCML_WINDOWS[k], MCML_WINDOWS[k + 1]);
                let rel = ours / c.windows[k] - 1.0;
                let z = (ours - c.windows[k]) / se_w[k];
                if name == "grid" && se_w[k] < 0.05 * c.windows[k] {
                    z_all.push(z);
                }
                cells.push(format!("{:+.1} % ({:+.1})", 100.0 * rel, z));
            }
            let dt = m.rd_total() - c.total;
            println!(
                "| {} | {} | {} | {name} | {:+.4} ({:+.1}) | {} |",
                c.g,
                c.eta,
                c.ap,
                dt,
                dt / se_t,
                cells.join(" | ")
            );
        }
    }
    let n = z_all.len() as f64;
    let rms = (z_all.iter().map(|z| z * z).sum::<f64>() / n).sqrt();
    println!("grid windows with MCML s.e. < 5 %: {n} windows, RMS z = {rms:.2}");
}

/// RMS relative difference of Rd per window and the total difference, model a against model b.
fn compare(a: &dyn ProfileModel, b: &dyn ProfileModel) -> (Vec<f64>, f64) {
    let w = WINDOWS
        .iter()
        .map(|&(lo, hi)| {
            let n = 24;
            let s: f64 = (0..n)
                .map(|i| {
                    let r = lo * (hi / lo).powf((i as f64 + 0.5) / n as f64);
                    (a.rd(r) / b.rd(r) - 1.0).powi(2)
                })
                .sum();
            (s / n as f64).sqrt()
        })
        .collect();
    (w, a.rd_total() - b.rd_total())
}

fn print_compare(label: &str, a: &McTableSet, b: &McTableSet, eta: f64) {
    for ap in ALBEDOS {
        let p = OpticalProperties::new(ap, 1.0 - ap, eta).unwrap();
        let (Ok(ma), Ok(mb)) = (McProfile::new(a, &p), McProfile::new(b, &p)) else {
            continue;
        };
        let (w, dt) = compare(&ma, &mb);
        let cells: Vec<String> = w.iter().map(|x| format!("{:.2} %", 100.0 * x)).collect();
        println!(
            "| {label} | {eta} | {ap} | {} | {dt:+.1e} |",
            cells.join(" | ")
        );
    }
}

fn eta_loo() {
    let grid = McGridSet::bundled().unwrap();
    let set = &grid.nodes()[2];
    assert_eq!(set.g(), 0.9);
    println!("| case | η | α′ | [0.3,1) | [1,3) | [3,10) | [10,20) | total |");
    println!("|---|---|---|---|---|---|---|---|");
    for eta in [1.1, 1.2, 1.3, 1.4, 1.5, 1.6] {
        let without: Vec<McTable> = set
            .tables()
            .iter()
            .filter(|t| (t.spec().eta - eta).abs() > 1e-9)
            .cloned()
            .collect();
        let held = McTableSet::new(vec![
            set.tables()
                .iter()
                .find(|t| (t.spec().eta - eta).abs() < 1e-9)
                .unwrap()
                .clone(),
        ])
        .unwrap();
        print_compare(
            "0.1 grid, one out",
            &McTableSet::new(without).unwrap(),
            &held,
            eta,
        );
    }
    let coarse: Vec<McTable> = set
        .tables()
        .iter()
        .filter(|t| ((t.spec().eta * 10.0).round() as i64) % 2 == 0)
        .cloned()
        .collect();
    let coarse = McTableSet::new(coarse).unwrap();
    for eta in [1.1, 1.3, 1.5] {
        let held = McTableSet::new(vec![
            set.tables()
                .iter()
                .find(|t| (t.spec().eta - eta).abs() < 1e-9)
                .unwrap()
                .clone(),
        ])
        .unwrap();
        print_compare("0.2 grid", &coarse, &held, eta);
    }
    let _ = bundled::BUNDLED_G.len();
}

/// The sparse η layouts against the shipped g = 0.8 / 0.9 tables they leave out (module docs).
fn eta_coarse() {
    let grid = McGridSet::bundled().unwrap();
    println!("| g | layout | η | α′ | [0.3,1) | [1,3) | [3,10) | [10,20) | total |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let layouts: [(&str, &[f64]); 2] = [
        ("1.0/1.4/1.8/2.4", &[1.0, 1.4, 1.8, 2.4]),
        ("+1.05/1.1/1.2", &[1.0, 1.05, 1.1, 1.2, 1.4, 1.8, 2.4]),
    ];
    for set in grid.nodes().iter().filter(|s| s.g() == 0.8 || s.g() == 0.9) {
        let pick = |eta: f64| {
            set.tables()
                .iter()
                .find(|t| (t.spec().eta - eta).abs() < 1e-6)
                .cloned()
        };
        for (name, etas) in layouts {
            let Some(sub) = etas.iter().map(|&e| pick(e)).collect::<Option<Vec<_>>>() else {
                println!(
                    "| {} | {name} | (a node is not shipped at this g) |",
                    set.g()
                );
                continue;
            };
            let sub = McTableSet::new(sub).unwrap();
            for held in [1.2, 1.6, 2.0, 2.2] {
                if etas.contains(&held) {
                    continue;
                }
                let Some(t) = pick(held) else { continue };
                let label = format!("{} | {name}", set.g());
                print_compare(&label, &sub, &McTableSet::new(vec![t]).unwrap(), held);
            }
        }
    }
}

fn table(path: &str, max_step: Option<f64>) {
    let t = McTable::load(std::path::Path::new(path)).expect("table");
    let (eta, g) = (t.spec().eta, t.spec().g);
    let grid = grid(max_step);
    let set = McTableSet::new(vec![t]).unwrap();
    println!("grid at g = {g}, η = {eta} against {path}");
    println!("| α′ | [0.3,1) | [1,3) | [3,10) | [10,20) | total |");
    println!("|---|---|---|---|---|---|");
    for ap in ALBEDOS {
        let p = OpticalProperties::new(ap, 1.0 - ap, eta)
            .unwrap()
            .with_g(g)
            .unwrap();
        if set.tables()[0]
            .rd_total(albedo_from_reduced(ap, g))
            .is_err()
        {
            continue;
        }
        let (Ok(ma), Ok(mb)) = (grid.profile(&p), McProfile::new(&set, &p)) else {
            println!("| {ap} | outside |");
            continue;
        };
        let (w, dt) = compare(&ma, &mb);
        let cells: Vec<String> = w.iter().map(|x| format!("{:.2} %", 100.0 * x)).collect();
        println!("| {ap} | {} | {dt:+.1e} |", cells.join(" | "));
    }
}

fn cost() {
    let t = std::time::Instant::now();
    let grid = McGridSet::bundled().unwrap();
    println!(
        "McGridSet::bundled: {:.1} ms",
        1e3 * t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    let _ = McTableSet::bundled().unwrap();
    println!(
        "McTableSet::bundled (g = 0 only): {:.1} ms",
        1e3 * t.elapsed().as_secs_f64()
    );
    let radii: Vec<f64> = (0..300).map(|i| 0.5 + 0.05 * i as f64).collect();
    let mut out = vec![scatterfit_optics::ProfileSample::ZERO; radii.len()];
    for g in [0.0, 0.9, 0.85] {
        let n = 20_000;
        let t = std::time::Instant::now();
        for i in 0..n {
            let p = OpticalProperties::new(1.0 + 1e-6 * i as f64, 0.02, 1.45)
                .unwrap()
                .with_g(g)
                .unwrap();
            ModelFamily::eval(&grid, &p, &radii, &mut out);
        }
        println!(
            "eval, 300 radii, g = {g}: {:.1} µs",
            1e6 * t.elapsed().as_secs_f64() / n as f64
        );
    }
}
