//! The evidence's figures as SVG, drawn with `plotters` through its SVG backend only: text
//! goes out as SVG `<text>` and the browser picks the font, so drawing needs no system fonts
//! (the crate's font-free "naive" layout sizes the labels).

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Line colours, one per series, distinguishable in print (Tableau 10).
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

pub fn colour(i: usize) -> RGBColor {
    COLOURS[i % COLOURS.len()]
}

/// Bias² and variance against k of one kernel variant: `(k, bias², variance)`.
pub type KSeries = (String, Vec<(f64, f64, f64)>);

/// One named line of points.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

fn err(path: &Path) -> impl Fn(String) -> String + '_ {
    move |e| format!("{}: cannot draw the plot: {e}", path.display())
}

/// The positive range of `v`, widened a little on a log scale; `None` if nothing is positive.
fn log_range(v: impl Iterator<Item = f64>) -> Option<std::ops::Range<f64>> {
    let (lo, hi) = v
        .filter(|x| *x > 0.0 && x.is_finite())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (hi > 0.0).then(|| lo / 1.5..hi * 1.5)
}

/// The log range `r` extended upwards so that a legend of `lines` lines (about 17 pixels
/// each on a 560-pixel plot) sits above the data instead of over it.
fn above_for_legend(r: std::ops::Range<f64>, lines: usize) -> std::ops::Range<f64> {
    let share = ((lines as f64 * 17.0 + 20.0) / 470.0).min(0.7);
    r.start..r.end * (r.end / r.start).powf(share / (1.0 - share))
}

type LogChart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// A white log-log chart over `root` with its title, grid and axis descriptions.
fn log_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
    (xr, yr): (std::ops::Range<f64>, std::ops::Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<LogChart<'a, 'b>, String> {
    root.fill(&WHITE).map_err(|x| x.to_string())?;
    // Within one decade a log axis only has labels between the powers of ten.
    let decades = yr.end / yr.start > 10.0;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(xr.log_scale(), yr.log_scale())
        .map_err(|x| x.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .y_label_formatter(&|v| {
            if decades {
                format!("{v:.0e}")
            } else {
                format!("{v:.3}")
            }
        })
        .x_label_formatter(&|v| format!("{v}"))
        .draw()
        .map_err(|x| x.to_string())?;
    Ok(chart)
}

/// The legend (above the data: see [`above_for_legend`]), then the file written.
fn finish<'a, 'b>(
    mut chart: LogChart<'a, 'b>,
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|x| x.to_string())?;
    root.present().map_err(|x| x.to_string())
}

/// Log-log lines of `series`, with dashed reference lines of the given `slopes` (each
/// through the middle of the data) and a legend. Points that are not positive are left out.
pub fn log_log(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[Series],
    slopes: &[(f64, &str)],
) -> Result<(), String> {
    let e = err(path);
    let points = || series.iter().flat_map(|s| s.points.iter());
    let (Some(xr), Some(yr)) = (
        log_range(points().map(|p| p.0)),
        log_range(points().map(|p| p.1)),
    ) else {
        return Err(e("no positive point".into()));
    };
    let data_y = yr.clone();
    let yr = above_for_legend(yr, series.len() + slopes.len());
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    let mut chart =
        log_chart(&root, title, (xr.clone(), yr.clone()), (x_desc, y_desc)).map_err(&e)?;
    // Reference slopes through the geometric centre of the data, clipped to the plot.
    let (cx, cy) = (
        (xr.start * xr.end).sqrt(),
        (data_y.start * data_y.end).sqrt(),
    );
    for (i, &(slope, label)) in slopes.iter().enumerate() {
        let x_at = |y: f64| cx * (y / cy).powf(1.0 / slope);
        let (xa, xb) = (x_at(yr.end), x_at(yr.start));
        let (x0, x1) = (xa.min(xb).max(xr.start), xa.max(xb).min(xr.end));
        if x0.partial_cmp(&x1) != Some(std::cmp::Ordering::Less) {
            continue;
        }
        let line = vec![
            (x0, cy * (x0 / cx).powf(slope)),
            (x1, cy * (x1 / cx).powf(slope)),
        ];
        let grey = RGBColor(90, 90, 90).mix(if i == 0 { 0.9 } else { 0.5 });
        chart
            .draw_series(DashedLineSeries::new(line, 6, 4, grey.stroke_width(1)))
            .map_err(|x| e(x.to_string()))?
            .label(label.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
    }
    for (i, s) in series.iter().enumerate() {
        let c = colour(i);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| p.0 > 0.0 && p.1 > 0.0)
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(|x| e(x.to_string()))?
            .label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(|x| e(x.to_string()))?;
    }
    finish(chart, &root).map_err(e)
}

/// Bias² (solid) and variance (dashed) against k, one colour per kernel variant, log-log.
pub fn bias_variance_k(path: &Path, title: &str, series: &[KSeries]) -> Result<(), String> {
    let e = err(path);
    let all = || series.iter().flat_map(|s| s.1.iter());
    let (Some(xr), Some(yr)) = (
        log_range(all().map(|p| p.0)),
        log_range(all().flat_map(|p| [p.1, p.2])),
    ) else {
        return Err(e("no positive point".into()));
    };
    let yr = above_for_legend(yr, series.len());
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    let axes = (
        "k (photons per estimate)",
        "relative bias^2 (solid), variance (dashed)",
    );
    let mut chart = log_chart(&root, title, (xr, yr), axes).map_err(&e)?;
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = colour(i);
        let bias: Vec<(f64, f64)> = pts
            .iter()
            .filter(|p| p.1 > 0.0)
            .map(|p| (p.0, p.1))
            .collect();
        let var: Vec<(f64, f64)> = pts
            .iter()
            .filter(|p| p.2 > 0.0)
            .map(|p| (p.0, p.2))
            .collect();
        chart
            .draw_series(LineSeries::new(bias.clone(), c.stroke_width(2)))
            .map_err(|x| e(x.to_string()))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(bias.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(|x| e(x.to_string()))?;
        chart
            .draw_series(DashedLineSeries::new(var.clone(), 6, 4, c.stroke_width(2)))
            .map_err(|x| e(x.to_string()))?;
        chart
            .draw_series(var.iter().map(|&p| Circle::new(p, 3, c.stroke_width(1))))
            .map_err(|x| e(x.to_string()))?;
    }
    finish(chart, &root).map_err(e)
}

/// One panel per region: a bar per technique, bias² (dark) stacked under variance (light),
/// so each bar's height is the MSE. `bars[t].1[r]` is technique t's (bias², variance) in
/// region r.
pub fn region_bars(
    path: &Path,
    title: &str,
    regions: &[&str],
    bars: &[(String, Vec<(f64, f64)>)],
) -> Result<(), String> {
    let e = err(path);
    let cols = 3;
    let rows = regions.len().div_ceil(cols).max(1);
    let legend_rows = bars.len().div_ceil(2) as u32;
    let legend_h = 12 + 18 * legend_rows;
    let root = SVGBackend::new(path, (1050, 40 + 300 * rows as u32 + legend_h)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|x| e(x.to_string()))?;
    let (panels, legend) = root.split_vertically(root.dim_in_pixel().1 - legend_h);
    for (r, (name, area)) in regions
        .iter()
        .zip(panels.split_evenly((rows, cols)))
        .enumerate()
    {
        panel(&area, name, r, bars).map_err(&e)?;
    }
    // The legend: one swatch per technique.
    for (i, (name, _)) in bars.iter().enumerate() {
        let x = 10 + (i as i32 % 2) * 520;
        let y = 4 + (i as i32 / 2) * 18;
        legend
            .draw(&Rectangle::new(
                [(x, y), (x + 12, y + 10)],
                colour(i).filled(),
            ))
            .map_err(|x| e(x.to_string()))?;
        legend
            .draw(&Text::new(
                name.clone(),
                (x + 16, y),
                ("sans-serif", 12).into_font(),
            ))
            .map_err(|x| e(x.to_string()))?;
    }
    root.present().map_err(|x| e(x.to_string()))
}

fn panel(
    area: &DrawingArea<SVGBackend, Shift>,
    name: &str,
    r: usize,
    bars: &[(String, Vec<(f64, f64)>)],
) -> Result<(), String> {
    let top = bars
        .iter()
        .map(|b| b.1.get(r).map_or(0.0, |&(x, y)| x + y))
        .fold(0.0f64, f64::max)
        .max(1e-12)
        * 1.1;
    let n = bars.len();
    let mut chart = ChartBuilder::on(area)
        .caption(name, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(10)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..n as f64, 0.0..top)
        .map_err(|x| x.to_string())?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|x| x.to_string())?;
    for (i, (_, v)) in bars.iter().enumerate() {
        let Some(&(b, var)) = v.get(r) else { continue };
        let c = colour(i);
        let (x0, x1) = (i as f64 + 0.15, i as f64 + 0.85);
        chart
            .draw_series([
                Rectangle::new([(x0, 0.0), (x1, b)], c.filled()),
                Rectangle::new([(x0, b), (x1, b + var)], c.mix(0.35).filled()),
            ])
            .map_err(|x| x.to_string())?;
    }
    Ok(())
}
