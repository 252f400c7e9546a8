//! Time against error: `twinpath bench` renders a scene at 1, 2, 4, ... spp per variant and
//! backend, several seeds at low spp, and records wall time (set-up and render apart), relMSE
//! and RMSE against a reference (the definitions of `twinpath diff`) and efficiency
//! 1 / (relMSE x render seconds); it writes a CSV and a log-log plot of error against time.

pub mod rays;

use crate::film::{diff_images, RgbImage};
use crate::render::{render, Backend, RenderOptions};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use anyhow::{anyhow, bail, Context, Result};
use std::io::Write;
use std::path::Path;

/// A named set of integrator settings to compare.
#[derive(Clone, Debug)]
pub struct Variant {
    pub name: String,
    pub settings: RenderSettings,
}

impl Variant {
    /// Parses `NAME` or `NAME:key=value,key=value` on top of `base`; the keys and values are
    /// the settings' vocabulary (`crate::settings::SETTINGS`).
    pub fn parse(spec: &str, base: &RenderSettings) -> Result<Variant> {
        let (name, rest) = spec.split_once(':').unwrap_or((spec, ""));
        if name.is_empty() {
            bail!("--variant {spec:?}: empty name");
        }
        let mut settings = *base;
        for kv in rest.split(',').filter(|kv| !kv.is_empty()) {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| anyhow!("--variant {spec:?}: {kv:?} is not key=value"))?;
            settings
                .set(k, v)
                .map_err(|m| anyhow!("--variant {spec:?}: {k}: {m}"))?;
        }
        Ok(Variant {
            name: name.to_string(),
            settings,
        })
    }
}

/// What to sweep.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    pub variants: Vec<Variant>,
    pub backends: Vec<Backend>,
    /// Largest spp rendered (the sweep doubles from 1).
    pub max_spp: u32,
    /// A curve stops once one of its renders took longer than this.
    pub max_seconds: f64,
    /// Independent seeds per point at spp <= 8 (1 above).
    pub seeds: u32,
}

/// One render of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    pub variant: String,
    pub backend: Backend,
    pub spp: u32,
    pub seed: u32,
    pub setup_s: f64,
    pub render_s: f64,
    pub relmse: f64,
    pub rmse: f64,
    /// 1 / (relMSE x render seconds).
    pub efficiency: f64,
}

/// Runs the sweep over `scene` (each variant's settings replace the scene file's); `progress`
/// is told about every render.
pub fn run_bench(
    scene: &Scene,
    reference: &RgbImage,
    cfg: &BenchConfig,
    mut progress: impl FnMut(&BenchRow),
) -> Result<Vec<BenchRow>> {
    if (reference.width, reference.height) != (scene.camera.width, scene.camera.height) {
        bail!(
            "reference is {}x{}, the scene renders {}x{}",
            reference.width,
            reference.height,
            scene.camera.width,
            scene.camera.height
        );
    }
    let mut rows = Vec::new();
    for variant in &cfg.variants {
        for &backend in &cfg.backends {
            let mut spp = 1;
            while spp <= cfg.max_spp {
                let seeds = if spp <= 8 { cfg.seeds.max(1) } else { 1 };
                let mut slowest: f64 = 0.0;
                for k in 0..seeds {
                    let mut settings = variant.settings;
                    settings.spp = spp;
                    settings.seed = variant.settings.seed.wrapping_add(1 + k);
                    let opts = RenderOptions {
                        backend,
                        ..Default::default()
                    };
                    let out = render(scene, &settings, &opts)?;
                    let d = diff_images(&RgbImage::from_film(&out.film), reference)?;
                    let render_s = out.render.as_secs_f64();
                    let row = BenchRow {
                        variant: variant.name.clone(),
                        backend: out.backend,
                        spp,
                        seed: settings.seed,
                        setup_s: out.setup.as_secs_f64(),
                        render_s,
                        relmse: d.relmse,
                        rmse: d.rmse,
                        efficiency: 1.0 / (d.relmse * render_s).max(f64::MIN_POSITIVE),
                    };
                    progress(&row);
                    rows.push(row);
                    slowest = slowest.max(render_s);
                }
                if slowest > cfg.max_seconds {
                    break;
                }
                spp *= 2;
            }
        }
    }
    Ok(rows)
}

/// Writes the rows as CSV with a header line.
pub fn write_csv(rows: &[BenchRow], path: &Path) -> Result<()> {
    let mut f = std::io::BufWriter::new(
        std::fs::File::create(path)
            .with_context(|| format!("{}: cannot create", path.display()))?,
    );
    writeln!(
        f,
        "variant,backend,spp,seed,setup_s,render_s,relmse,rmse,efficiency"
    )?;
    for r in rows {
        writeln!(
            f,
            "{},{:?},{},{},{:.6},{:.6},{:.6e},{:.6e},{:.6e}",
            r.variant,
            r.backend,
            r.spp,
            r.seed,
            r.setup_s,
            r.render_s,
            r.relmse,
            r.rmse,
            r.efficiency
        )?;
    }
    Ok(())
}

/// One point per (variant, backend, spp): the mean render time and relMSE over its seeds,
/// curves and points in the order they first appear.
pub fn curves(rows: &[BenchRow]) -> Vec<(String, Vec<(f64, f64)>)> {
    /// Sums over the seeds of one point.
    struct Point {
        spp: u32,
        time: f64,
        relmse: f64,
        renders: f64,
    }
    let mut sums: Vec<(String, Vec<Point>)> = Vec::new();
    for r in rows {
        let label = format!("{} ({:?})", r.variant, r.backend).to_lowercase();
        let i = match sums.iter().position(|(l, _)| *l == label) {
            Some(i) => i,
            None => {
                sums.push((label, Vec::new()));
                sums.len() - 1
            }
        };
        let points = &mut sums[i].1;
        match points.iter_mut().find(|p| p.spp == r.spp) {
            Some(p) => {
                p.time += r.render_s;
                p.relmse += r.relmse;
                p.renders += 1.0;
            }
            None => points.push(Point {
                spp: r.spp,
                time: r.render_s,
                relmse: r.relmse,
                renders: 1.0,
            }),
        }
    }
    sums.into_iter()
        .map(|(label, points)| {
            let curve = points
                .iter()
                .map(|p| (p.time / p.renders, p.relmse / p.renders))
                .collect();
            (label, curve)
        })
        .collect()
}

/// The font the plot's text uses: DejaVu Sans from Debian's fonts-dejavu-core
/// (scripts/setup.sh installs it).
pub const PLOT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Draws relMSE against render time, log-log, one curve per variant and backend, as PNG, and
/// says whether it did: `Ok(false)`, with no file written, where no row has both a positive
/// time and a positive relMSE (a render equal to its reference has nothing to place on a log
/// scale), which is an outcome of the sweep, not an error; the CSV holds those rows.
pub fn write_plot(rows: &[BenchRow], title: &str, path: &Path) -> Result<bool> {
    use plotters::prelude::*;
    static FONT: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    FONT.get_or_init(|| {
        let bytes = std::fs::read(PLOT_FONT).map_err(|e| format!("{PLOT_FONT}: {e}"))?;
        plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            Box::leak(bytes.into_boxed_slice()),
        )
        .map_err(|_| format!("{PLOT_FONT}: not a font"))
    })
    .clone()
    .map_err(|e| anyhow!("cannot load the plot font ({e}); install fonts-dejavu-core"))?;

    let curves = curves(rows);
    let pts = curves.iter().flat_map(|(_, c)| c.iter().copied());
    let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (t, e) in pts {
        if t > 0.0 && e > 0.0 {
            (t0, t1, e0, e1) = (t0.min(t), t1.max(t), e0.min(e), e1.max(e));
        }
    }
    if t0 > t1 {
        return Ok(false);
    }
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (t0 / 1.5..t1 * 1.5).log_scale(),
            (e0 / 1.5..e1 * 1.5).log_scale(),
        )
        .map_err(|e| anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("render time (s)")
        .y_desc("relMSE")
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    for (i, (label, c)) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(c.iter().copied(), color.stroke_width(2)))
            .map_err(|e| anyhow!("{e}"))?
            .label(label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart
            .draw_series(c.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(|e| anyhow!("{e}"))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    root.present()
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(true)
}
