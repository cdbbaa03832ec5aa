//! `overrun.svg`: per scene (and per scene with the hostile client), how late its frames
//! were at each budget: the share of answered frames whose in-daemon time overran the
//! budget by more than `x` µs, one line per budget (log-scaled overrun). A budget whose
//! frames were all on time has no line; its legend entry says so.

use crate::report::Row;
use plotters::prelude::*;
use std::error::Error;
use std::path::Path;

/// Writes the plot of `rows` to `path`.
///
/// # Errors
/// The file could not be written.
pub fn plot_overruns(path: &Path, rows: &[Row]) -> Result<(), Box<dyn Error>> {
    let mut panels: Vec<String> = Vec::new();
    for row in rows {
        let label = row.scene_label();
        if !panels.contains(&label) {
            panels.push(label);
        }
    }
    let columns = 2.min(panels.len().max(1));
    let lines = panels.len().div_ceil(columns).max(1);
    let root =
        SVGBackend::new(path, (560 * columns as u32, 340 * lines as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((lines, columns));
    for (panel, area) in panels.iter().zip(&areas) {
        let panel_rows: Vec<&Row> = rows.iter().filter(|r| &r.scene_label() == panel).collect();
        draw_panel(area, panel, &panel_rows)?;
    }
    root.present()?;
    Ok(())
}

/// One scene's panel: a survival curve of the overrun per budget.
fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    title: &str,
    rows: &[&Row],
) -> Result<(), Box<dyn Error>> {
    let max_us = rows
        .iter()
        .flat_map(|r| r.overruns_us())
        .fold(10.0, f64::max)
        * 1.5;
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{title}: share of frames late by more than x"),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d((1.0..max_us).log_scale(), 0.0..1.05)?;
    chart
        .configure_mesh()
        .x_desc("overrun past the budget (in daemon), µs")
        .y_desc("share of frames")
        .draw()?;
    for (i, row) in rows.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let total = row.overruns_us().len().max(1) as f64;
        let mut late: Vec<f64> = row.overruns_us().into_iter().filter(|&x| x > 0.0).collect();
        late.sort_by(f64::total_cmp);
        let label = if late.is_empty() {
            format!("{} µs: all on time", row.budget_us)
        } else {
            format!("{} µs", row.budget_us)
        };
        // Late by more than x: a step down at each late frame's overrun.
        let mut points = Vec::with_capacity(2 * late.len() + 1);
        let mut above = late.len() as f64 / total;
        points.push((1.0, above));
        for &x in &late {
            let x = x.max(1.0);
            points.push((x, above));
            above -= 1.0 / total;
            points.push((x, above));
        }
        chart
            .draw_series(LineSeries::new(
                points.into_iter().filter(|_| !late.is_empty()),
                colour,
            ))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    Ok(())
}
