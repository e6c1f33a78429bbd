//! Static SVG line charts for documentation figures.
//!
//! This module renders simple, publication-quality 2-D charts (time histories,
//! work-precision log-log diagrams, empirical CDFs, ...) to standalone SVG
//! text without any external dependency.
//!
//! Features:
//! * linear or base-10 logarithmic axes with "nice" ticks (1, 2, 5 × 10^k) or
//!   decades (with minor ticks 2..9 when there is room);
//! * automatic ranges from the finite data (NaN/inf points, and non-positive
//!   values on log axes, are skipped and split a series into separate pieces);
//! * the colour-blind-safe Okabe–Ito palette, distinct marker shapes, and a
//!   legend placed in the least crowded corner of the plot area;
//! * dashed grey reference lines with labels;
//! * min/max-per-pixel-column decimation of long series, so that a series
//!   with a million points still yields a small file while keeping its
//!   visual envelope.
//!
//! ```
//! use polhode::plot::{Chart, Series, Style};
//! let mut chart = Chart::new("Nutation", "time [s]", "angle [deg]");
//! chart.series.push(Series::new("rigid", vec![(0.0, 1.0), (1.0, 0.5)], Style::Line));
//! let svg = chart.to_svg(640, 400);
//! assert!(svg.starts_with("<svg"));
//! ```

use std::fmt::Write as _;

/// Scale of a chart axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear axis.
    #[default]
    Linear,
    /// Base-10 logarithmic axis; non-positive values are not drawn.
    Log10,
}

/// Drawing style of a data series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Style {
    /// Solid line through the points.
    #[default]
    Line,
    /// Markers only, one per point.
    Markers,
    /// Solid line with a marker at every point.
    LineMarkers,
    /// Dashed line through the points.
    Dashed,
}

/// Which axis a [`ReferenceLine`] is attached to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// A vertical line at a given x value.
    X,
    /// A horizontal line at a given y value.
    Y,
}

/// One named data series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Name shown in the legend (series with an empty name are not listed).
    pub name: String,
    /// Data points `(x, y)` in drawing order. Non-finite points (and
    /// non-positive values on log axes) break the line into pieces.
    pub points: Vec<(f64, f64)>,
    /// How the series is drawn.
    pub style: Style,
}

impl Series {
    /// Creates a series from a name, its points and a style.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Series {
            name: name.into(),
            points,
            style,
        }
    }
}

/// A dashed grey horizontal or vertical line with a label, e.g. a tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceLine {
    /// [`Axis::X`] for a vertical line at `x = value`, [`Axis::Y`] for a
    /// horizontal line at `y = value`.
    pub axis: Axis,
    /// Position of the line in data units.
    pub value: f64,
    /// Text drawn next to the line (may be empty).
    pub label: String,
}

impl ReferenceLine {
    /// Creates a reference line.
    pub fn new(axis: Axis, value: f64, label: impl Into<String>) -> Self {
        ReferenceLine {
            axis,
            value,
            label: label.into(),
        }
    }
}

/// A line chart that can be rendered to SVG with [`Chart::to_svg`].
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Title above the plot area (omitted when empty).
    pub title: String,
    /// Label of the horizontal axis (omitted when empty).
    pub x_label: String,
    /// Label of the vertical axis (omitted when empty).
    pub y_label: String,
    /// Scale of the horizontal axis.
    pub x_scale: Scale,
    /// Scale of the vertical axis.
    pub y_scale: Scale,
    /// Data series, drawn in order with palette colours by index.
    pub series: Vec<Series>,
    /// Fixed x range `(min, max)`; `None` derives it from the data and the
    /// vertical reference lines. Invalid ranges (non-finite, or non-positive
    /// on a log axis) fall back to the automatic range.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range `(min, max)`; `None` derives it from the data (within the
    /// x range, if fixed) and the horizontal reference lines.
    pub y_range: Option<(f64, f64)>,
    /// Dashed reference lines with labels.
    pub reference_lines: Vec<ReferenceLine>,
}

/// Okabe–Ito colour-blind-safe palette, reordered so that the colours with
/// the best contrast on white come first (yellow last).
const PALETTE: [&str; 12] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
    "#882255", "#44AA99", "#999933", "#AA4499",
];
/// Series with more finite points than this are decimated for drawing.
const DECIMATE_THRESHOLD: usize = 4000;
const FONT_TICK: f64 = 11.0;
const FONT_LABEL: f64 = 13.0;
const FONT_TITLE: f64 = 16.0;
const FONT_LEGEND: f64 = 12.0;
/// Average glyph advance as a fraction of the font size (for layout only).
const CHAR_W: f64 = 0.6;
const TICK_LEN: f64 = 5.0;
const LINE_WIDTH: f64 = 1.6;
const MARKER_R: f64 = 3.5;
const LEGEND_ROW: f64 = 18.0;
const LEGEND_SAMPLE: f64 = 26.0;

impl Chart {
    /// Creates an empty chart with linear axes, no series, automatic ranges
    /// and no reference lines.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: Vec::new(),
            x_range: None,
            y_range: None,
            reference_lines: Vec::new(),
        }
    }

    /// Renders the chart as a standalone SVG document of `width` × `height`
    /// pixels (also used as the `viewBox`).
    pub fn to_svg(&self, width: u32, height: u32) -> String {
        let w = f64::from(width);
        let h = f64::from(height);
        let lay = self.layout(w, h);
        let pieces: Vec<Vec<Vec<(f64, f64)>>> =
            self.series.iter().map(|s| series_pieces(s, &lay)).collect();

        let mut out = String::with_capacity(16 * 1024);
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
             viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"{}\">",
            num(FONT_TICK)
        );
        if !self.title.is_empty() {
            let _ = writeln!(out, "<title>{}</title>", escape(&self.title));
        }
        let clip_id = format!("polhode-clip-{:08x}", self.clip_hash(width, height));
        let _ = writeln!(
            out,
            "<defs><clipPath id=\"{clip_id}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath></defs>",
            num(lay.left),
            num(lay.top),
            num(lay.right - lay.left),
            num(lay.bottom - lay.top)
        );
        let _ = writeln!(
            out,
            "<rect x=\"0\" y=\"0\" width=\"{width}\" height=\"{height}\" fill=\"white\"/>"
        );

        self.write_grid(&mut out, &lay);
        self.write_reference_lines(&mut out, &lay);

        let _ = writeln!(out, "<g clip-path=\"url(#{clip_id})\">");
        for (i, (s, ps)) in self.series.iter().zip(&pieces).enumerate() {
            write_series(&mut out, i, s.style, ps);
        }
        out.push_str("</g>\n");

        self.write_axes(&mut out, &lay);
        let legend = self.legend_rect(&lay, &pieces);
        self.write_reference_labels(&mut out, &lay, legend.as_ref());
        self.write_legend(&mut out, legend.as_ref());
        out.push_str("</svg>\n");
        out
    }

    /// Small hash of the chart so that several charts inlined in one HTML page
    /// do not share clip-path ids.
    fn clip_hash(&self, width: u32, height: u32) -> u32 {
        let mut hsh: u32 = 0x811c_9dc5;
        let mut feed = |b: u8| {
            hsh ^= u32::from(b);
            hsh = hsh.wrapping_mul(0x0100_0193);
        };
        for b in self.title.bytes().chain(self.x_label.bytes()) {
            feed(b);
        }
        for b in self.y_label.bytes() {
            feed(b);
        }
        for s in &self.series {
            for b in s.name.bytes() {
                feed(b);
            }
            for b in (s.points.len() as u64).to_le_bytes() {
                feed(b);
            }
        }
        for b in width.to_le_bytes().into_iter().chain(height.to_le_bytes()) {
            feed(b);
        }
        hsh
    }

    /// Computes ranges, ticks, margins and the data-to-pixel mappings.
    fn layout(&self, w: f64, h: f64) -> Layout {
        let xlog = self.x_scale == Scale::Log10;
        let ylog = self.y_scale == Scale::Log10;

        let valid = || {
            self.series.iter().flat_map(|s| {
                s.points
                    .iter()
                    .filter_map(|&(x, y)| Some((transform(xlog, x)?, transform(ylog, y)?)))
            })
        };

        let mut xdata: Vec<f64> = valid().map(|(x, _)| x).collect();
        xdata.extend(
            self.reference_lines
                .iter()
                .filter(|r| r.axis == Axis::X)
                .filter_map(|r| transform(xlog, r.value)),
        );
        let line_only = self
            .series
            .iter()
            .all(|s| matches!(s.style, Style::Line | Style::Dashed));
        let xpad = if line_only { 0.0 } else { 0.04 };
        let xr = compute_range(xlog, self.x_range, &xdata, xpad);

        let fixed_x = self.x_range.is_some();
        let tol = (xr.1 - xr.0).abs() * 1e-9;
        let mut ydata: Vec<f64> = valid()
            .filter(|&(x, _)| !fixed_x || (x >= xr.0 - tol && x <= xr.1 + tol))
            .map(|(_, y)| y)
            .collect();
        ydata.extend(
            self.reference_lines
                .iter()
                .filter(|r| r.axis == Axis::Y)
                .filter_map(|r| transform(ylog, r.value)),
        );
        let yr = compute_range(ylog, self.y_range, &ydata, 0.05);

        // Approximate plot size, only used to choose the tick density.
        let approx_w = (w - 110.0).max(60.0);
        let approx_h = (h - 90.0).max(60.0);
        let x_ticks = make_ticks(xlog, xr, approx_w, 90.0, 48.0);
        let y_ticks = make_ticks(ylog, yr, approx_h, 50.0, 24.0);

        let y_label_w = y_ticks
            .iter()
            .map(|t| t.label.width(FONT_TICK))
            .fold(0.0, f64::max);
        let mut left = 8.0 + y_label_w + TICK_LEN + 4.0;
        if !self.y_label.is_empty() {
            left += FONT_LABEL + 8.0;
        }
        let top = if self.title.is_empty() {
            14.0
        } else {
            FONT_TITLE + 20.0
        };
        let mut bottom_margin = TICK_LEN + 4.0 + FONT_TICK + 10.0;
        if !self.x_label.is_empty() {
            bottom_margin += FONT_LABEL + 8.0;
        }
        let last_x_label = x_ticks
            .iter()
            .filter(|t| t.major)
            .map(|t| t.label.width(FONT_TICK))
            .next_back()
            .unwrap_or(0.0);
        let right_margin = (last_x_label / 2.0 + 6.0).max(18.0);

        let right = (w - right_margin).max(left + 1.0);
        let bottom = (h - bottom_margin).max(top + 1.0);

        Layout {
            x: AxisMap {
                log: xlog,
                lo: xr.0,
                hi: xr.1,
                p0: left,
                p1: right,
            },
            y: AxisMap {
                log: ylog,
                lo: yr.0,
                hi: yr.1,
                p0: bottom,
                p1: top,
            },
            x_ticks,
            y_ticks,
            left,
            top,
            right,
            bottom,
        }
    }

    fn write_grid(&self, out: &mut String, lay: &Layout) {
        let mut minor = String::new();
        let mut major = String::new();
        for t in &lay.x_ticks {
            let px = lay.x.px(t.t);
            let d = if t.major { &mut major } else { &mut minor };
            let _ = write!(d, "M{} {}V{}", num(px), num(lay.top), num(lay.bottom));
        }
        for t in &lay.y_ticks {
            let py = lay.y.px(t.t);
            let d = if t.major { &mut major } else { &mut minor };
            let _ = write!(d, "M{} {}H{}", num(lay.left), num(py), num(lay.right));
        }
        if !minor.is_empty() {
            let _ = writeln!(
                out,
                "<path d=\"{minor}\" stroke=\"#eeeeee\" stroke-width=\"0.7\" fill=\"none\"/>"
            );
        }
        if !major.is_empty() {
            let _ = writeln!(
                out,
                "<path d=\"{major}\" stroke=\"#dddddd\" stroke-width=\"0.8\" fill=\"none\"/>"
            );
        }
    }

    fn reference_positions(&self, lay: &Layout) -> Vec<(Axis, f64, &str)> {
        self.reference_lines
            .iter()
            .filter_map(|r| {
                let (map, lo, hi) = match r.axis {
                    Axis::X => (&lay.x, lay.left, lay.right),
                    Axis::Y => (&lay.y, lay.top, lay.bottom),
                };
                let p = map.map(r.value)?;
                (p >= lo - 0.5 && p <= hi + 0.5).then_some((r.axis, p, r.label.as_str()))
            })
            .collect()
    }

    fn write_reference_lines(&self, out: &mut String, lay: &Layout) {
        for (axis, p, _) in self.reference_positions(lay) {
            let (x1, y1, x2, y2) = match axis {
                Axis::X => (p, lay.top, p, lay.bottom),
                Axis::Y => (lay.left, p, lay.right, p),
            };
            let _ = writeln!(
                out,
                "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#777777\" \
                 stroke-width=\"1\" stroke-dasharray=\"5 4\"/>",
                num(x1),
                num(y1),
                num(x2),
                num(y2)
            );
        }
    }

    /// Writes the reference-line labels, each at the first candidate
    /// position (along the line) that does not collide with the legend.
    fn write_reference_labels(&self, out: &mut String, lay: &Layout, legend: Option<&Rect>) {
        let halo = "fill=\"#555555\" stroke=\"white\" stroke-width=\"3\" \
                    stroke-linejoin=\"round\" paint-order=\"stroke\"";
        let fs = FONT_TICK;
        for (axis, p, label) in self.reference_positions(lay) {
            if label.is_empty() {
                continue;
            }
            let tw = text_width(label, fs);
            let free = |r: &Rect| legend.is_none_or(|l| !l.overlaps(r));
            match axis {
                Axis::X => {
                    // Rotated text reading upwards, left or right of the line,
                    // at the top or the bottom of the plot area.
                    let (x_left, x_right) = (p - 4.0, p + 4.0 + fs * 0.75);
                    let (y_top, y_bot) = (lay.top + 6.0, lay.bottom - 6.0);
                    let cands = [
                        (x_left, y_top, "end"),
                        (x_right, y_top, "end"),
                        (x_left, y_bot, "start"),
                        (x_right, y_bot, "start"),
                    ];
                    let pick = cands
                        .iter()
                        .find(|&&(x, y, anchor)| {
                            let (y0, y1) = if anchor == "end" {
                                (y, y + tw)
                            } else {
                                (y - tw, y)
                            };
                            free(&Rect {
                                x0: x - fs,
                                y0,
                                x1: x,
                                y1,
                            })
                        })
                        .unwrap_or(&cands[0]);
                    let _ = writeln!(
                        out,
                        "<text transform=\"translate({} {}) rotate(-90)\" text-anchor=\"{}\" \
                         font-size=\"{}\" {halo}>{}</text>",
                        num(pick.0),
                        num(pick.1),
                        pick.2,
                        num(fs),
                        escape(label)
                    );
                }
                Axis::Y => {
                    // Above or below the line, at its left or right end.
                    let (y_above, y_below) = (p - 4.0, p + 4.0 + fs * 0.8);
                    let (x_l, x_r) = (lay.left + 6.0, lay.right - 6.0);
                    let above_ok = y_above - fs * 0.8 >= lay.top;
                    let cands = [
                        (x_l, y_above, "start", above_ok),
                        (x_r, y_above, "end", above_ok),
                        (x_l, y_below, "start", true),
                        (x_r, y_below, "end", true),
                    ];
                    let pick = cands
                        .iter()
                        .find(|&&(x, y, anchor, ok)| {
                            let (x0, x1) = if anchor == "start" {
                                (x, x + tw)
                            } else {
                                (x - tw, x)
                            };
                            ok && free(&Rect {
                                x0,
                                y0: y - fs * 0.8,
                                x1,
                                y1: y + fs * 0.2,
                            })
                        })
                        .unwrap_or(&cands[0]);
                    let _ = writeln!(
                        out,
                        "<text x=\"{}\" y=\"{}\" text-anchor=\"{}\" font-size=\"{}\" {halo}>{}</text>",
                        num(pick.0),
                        num(pick.1),
                        pick.2,
                        num(fs),
                        escape(label)
                    );
                }
            }
        }
    }

    fn write_axes(&self, out: &mut String, lay: &Layout) {
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444444\" stroke-width=\"1\"/>",
            num(lay.left),
            num(lay.top),
            num(lay.right - lay.left),
            num(lay.bottom - lay.top)
        );

        // Tick marks (outside the frame); minor ticks are shorter.
        let mut marks = String::new();
        for t in &lay.x_ticks {
            let len = if t.major { TICK_LEN } else { TICK_LEN * 0.6 };
            let _ = write!(
                marks,
                "M{} {}v{}",
                num(lay.x.px(t.t)),
                num(lay.bottom),
                num(len)
            );
        }
        for t in &lay.y_ticks {
            let len = if t.major { TICK_LEN } else { TICK_LEN * 0.6 };
            let _ = write!(
                marks,
                "M{} {}h{}",
                num(lay.left),
                num(lay.y.px(t.t)),
                num(-len)
            );
        }
        if !marks.is_empty() {
            let _ = writeln!(
                out,
                "<path d=\"{marks}\" stroke=\"#444444\" stroke-width=\"1\" fill=\"none\"/>"
            );
        }

        out.push_str("<g fill=\"#333333\">\n");
        let x_base = lay.bottom + TICK_LEN + 4.0 + FONT_TICK * 0.8;
        for t in lay.x_ticks.iter().filter(|t| t.major) {
            if let Some(content) = t.label.svg() {
                let _ = writeln!(
                    out,
                    "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{content}</text>",
                    num(lay.x.px(t.t)),
                    num(x_base)
                );
            }
        }
        for t in lay.y_ticks.iter().filter(|t| t.major) {
            if let Some(content) = t.label.svg() {
                let _ = writeln!(
                    out,
                    "<text x=\"{}\" y=\"{}\" dy=\"0.35em\" text-anchor=\"end\">{content}</text>",
                    num(lay.left - TICK_LEN - 3.0),
                    num(lay.y.px(t.t))
                );
            }
        }
        out.push_str("</g>\n");

        if !self.x_label.is_empty() {
            let _ = writeln!(
                out,
                "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"{}\" fill=\"#222222\">{}</text>",
                num((lay.left + lay.right) / 2.0),
                num(x_base + 8.0 + FONT_LABEL),
                num(FONT_LABEL),
                escape(&self.x_label)
            );
        }
        if !self.y_label.is_empty() {
            let _ = writeln!(
                out,
                "<text transform=\"translate({} {}) rotate(-90)\" text-anchor=\"middle\" font-size=\"{}\" fill=\"#222222\">{}</text>",
                num(8.0 + FONT_LABEL * 0.8),
                num((lay.top + lay.bottom) / 2.0),
                num(FONT_LABEL),
                escape(&self.y_label)
            );
        }
        if !self.title.is_empty() {
            let _ = writeln!(
                out,
                "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"{}\" font-weight=\"bold\" fill=\"#111111\">{}</text>",
                num((lay.left + lay.right) / 2.0),
                num(FONT_TITLE + 6.0),
                num(FONT_TITLE),
                escape(&self.title)
            );
        }
    }

    fn legend_entries(&self) -> Vec<(usize, &Series)> {
        self.series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.name.is_empty())
            .collect()
    }

    /// Legend box inside the plot area, in the corner that hides the least
    /// data and reference lines (ties prefer top-right, then top-left,
    /// bottom-right, bottom-left). `None` when no series has a name.
    fn legend_rect(&self, lay: &Layout, pieces: &[Vec<Vec<(f64, f64)>>]) -> Option<Rect> {
        let entries = self.legend_entries();
        if entries.is_empty() {
            return None;
        }
        let text_w = entries
            .iter()
            .map(|(_, s)| text_width(&s.name, FONT_LEGEND))
            .fold(0.0, f64::max);
        let bw = 8.0 + LEGEND_SAMPLE + 6.0 + text_w + 8.0;
        let bh = 6.0 + LEGEND_ROW * entries.len() as f64 + 2.0;
        let inset = 8.0;
        let corners = [
            (lay.right - inset - bw, lay.top + inset),
            (lay.left + inset, lay.top + inset),
            (lay.right - inset - bw, lay.bottom - inset - bh),
            (lay.left + inset, lay.bottom - inset - bh),
        ];
        let refs = self.reference_positions(lay);
        let mut best = None;
        let mut best_hits = usize::MAX;
        for &(x, y) in &corners {
            let rect = Rect {
                x0: x,
                y0: y,
                x1: x + bw,
                y1: y + bh,
            };
            let data_hits: usize = self
                .series
                .iter()
                .zip(pieces)
                .map(|(s, ps)| count_hits(s.style, ps, &rect))
                .sum();
            let ref_hits = refs
                .iter()
                .filter(|(axis, p, _)| match axis {
                    Axis::X => *p >= rect.x0 && *p <= rect.x1,
                    Axis::Y => *p >= rect.y0 && *p <= rect.y1,
                })
                .count();
            let hits = data_hits + 5 * ref_hits;
            if hits < best_hits {
                best_hits = hits;
                best = Some(rect);
            }
        }
        best
    }

    fn write_legend(&self, out: &mut String, rect: Option<&Rect>) {
        let Some(rect) = rect else {
            return;
        };
        let entries = self.legend_entries();
        let (bx, by, bw, bh) = (rect.x0, rect.y0, rect.x1 - rect.x0, rect.y1 - rect.y0);
        let _ = writeln!(
            out,
            "<g font-size=\"{}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" rx=\"2\" \
             fill=\"white\" fill-opacity=\"0.9\" stroke=\"#bbbbbb\" stroke-width=\"0.8\"/>",
            num(FONT_LEGEND),
            num(bx),
            num(by),
            num(bw),
            num(bh)
        );
        for (row, (i, s)) in entries.iter().enumerate() {
            let cy = by + 6.0 + LEGEND_ROW * (row as f64 + 0.5);
            let x0 = bx + 8.0;
            let x1 = x0 + LEGEND_SAMPLE;
            let color = PALETTE[i % PALETTE.len()];
            if s.style != Style::Markers {
                let _ = writeln!(
                    out,
                    "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{color}\" \
                     stroke-width=\"{}\"{}/>",
                    num(x0),
                    num(cy),
                    num(x1),
                    num(cy),
                    num(LINE_WIDTH),
                    dash_attr(s.style)
                );
            }
            if matches!(s.style, Style::Markers | Style::LineMarkers) {
                let mut d = String::new();
                marker_path(&mut d, *i, ((x0 + x1) / 2.0, cy));
                let _ = writeln!(out, "<path d=\"{d}\" fill=\"{color}\"/>");
            }
            let _ = writeln!(
                out,
                "<text x=\"{}\" y=\"{}\" dy=\"0.35em\" fill=\"#222222\">{}</text>",
                num(x1 + 6.0),
                num(cy),
                escape(&s.name)
            );
        }
        out.push_str("</g>\n");
    }
}

/// Resolved geometry of a chart.
#[derive(Debug, Clone)]
struct Layout {
    x: AxisMap,
    y: AxisMap,
    x_ticks: Vec<Tick>,
    y_ticks: Vec<Tick>,
    left: f64,
    top: f64,
    right: f64,
    bottom: f64,
}

/// Maps a data value (via its transformed value: identity or log10) to pixels.
#[derive(Debug, Clone, Copy)]
struct AxisMap {
    log: bool,
    /// Transformed range.
    lo: f64,
    hi: f64,
    /// Pixel positions of `lo` and `hi`.
    p0: f64,
    p1: f64,
}

impl AxisMap {
    fn px(&self, t: f64) -> f64 {
        let f = (t - self.lo) / (self.hi - self.lo);
        (self.p0 + f * (self.p1 - self.p0)).clamp(-1e6, 1e6)
    }

    fn map(&self, v: f64) -> Option<f64> {
        transform(self.log, v).map(|t| self.px(t))
    }
}

/// Identity or log10; `None` for values that cannot be drawn on the axis.
fn transform(log: bool, v: f64) -> Option<f64> {
    if !v.is_finite() {
        None
    } else if log {
        (v > 0.0).then(|| v.log10())
    } else {
        Some(v)
    }
}

/// Axis range in transformed units: the fixed range if usable, otherwise the
/// data extent padded by `pad` of its span; degenerate ranges are widened.
fn compute_range(log: bool, fixed: Option<(f64, f64)>, data: &[f64], pad: f64) -> (f64, f64) {
    let fixed = fixed.map(|(a, b)| (transform(log, a), transform(log, b)));
    if let Some((Some(ta), Some(tb))) = fixed {
        return widen_degenerate(log, ta.min(tb), ta.max(tb));
    }
    if data.is_empty() {
        return (0.0, 1.0);
    }
    let lo = data.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = data.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = widen_degenerate(log, lo, hi);
    let d = (hi - lo) * pad;
    let (plo, phi) = (lo - d, hi + d);
    if plo.is_finite() && phi.is_finite() {
        (plo, phi)
    } else {
        (lo, hi)
    }
}

fn widen_degenerate(log: bool, lo: f64, hi: f64) -> (f64, f64) {
    let scale = lo.abs().max(hi.abs());
    let span = hi - lo;
    if !span.is_finite() {
        // Only reachable for spans near f64::MAX: shrink to stay finite.
        return (lo / 2.0, hi / 2.0);
    }
    if span > scale * 1e-12 && span > 0.0 {
        return (lo, hi);
    }
    let c = lo + span / 2.0;
    let d = if log {
        0.5
    } else if c == 0.0 {
        1.0
    } else {
        c.abs() * 0.1
    };
    (c - d, c + d)
}

/// Exact power of ten (as parsed from decimal text).
fn pow10(e: i32) -> f64 {
    format!("1e{e}").parse().unwrap_or(f64::NAN)
}

/// "Nice" ticks (1, 2 or 5 × 10^k spacing) inside `[lo, hi]`, aiming for
/// about `target` intervals. Returns the tick values and the step.
fn linear_ticks(lo: f64, hi: f64, target: f64) -> (Vec<f64>, f64) {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return (Vec::new(), 0.0);
    }
    let raw = span / target.max(1.0);
    let e = raw.log10().floor() as i32;
    let base = pow10(e);
    let f = raw / base;
    let nice = if f < 1.5 {
        1.0
    } else if f < 3.0 {
        2.0
    } else if f < 7.0 {
        5.0
    } else {
        10.0
    };
    let step = nice * base;
    let k0 = (lo / step - 1e-9).ceil();
    let k1 = (hi / step + 1e-9).floor();
    if !(step > 0.0 && k0.is_finite() && k1.is_finite()) || k1 - k0 > 1000.0 {
        return (Vec::new(), 0.0);
    }
    let mut ticks = Vec::new();
    let mut k = k0;
    while k <= k1 {
        let v = k * step;
        ticks.push(if v.abs() < step * 1e-9 { 0.0 } else { v });
        k += 1.0;
    }
    (ticks, step)
}

/// Tick label.
#[derive(Debug, Clone, PartialEq)]
enum Label {
    None,
    Text(String),
    /// `10^e`, drawn with a superscript exponent.
    Pow10(i32),
}

impl Label {
    fn width(&self, font: f64) -> f64 {
        match self {
            Label::None => 0.0,
            Label::Text(s) => text_width(s, font),
            Label::Pow10(e) => {
                let digits = e.unsigned_abs().to_string().len() + usize::from(*e < 0);
                (2.0 + 0.75 * digits as f64) * font * CHAR_W
            }
        }
    }

    /// SVG text content, already escaped.
    fn svg(&self) -> Option<String> {
        match self {
            Label::None => None,
            Label::Text(s) => Some(escape(s)),
            Label::Pow10(e) => Some(format!(
                "10<tspan dy=\"-0.5em\" font-size=\"{}\">{}</tspan>",
                num(FONT_TICK * 0.75),
                minus(&e.to_string())
            )),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Tick {
    /// Position in transformed units.
    t: f64,
    major: bool,
    label: Label,
}

/// Ticks for one axis. `lin_px` and `log_px` are the desired minimum pixel
/// spacing of labelled ticks on linear and log axes.
fn make_ticks(log: bool, (lo, hi): (f64, f64), len: f64, lin_px: f64, log_px: f64) -> Vec<Tick> {
    if log {
        let max_labels = (len / log_px).max(2.0);
        let decade_px = len / (hi - lo);
        log_ticks(lo, hi, max_labels, decade_px)
    } else {
        let target = (len / lin_px).clamp(2.0, 10.0);
        let (vals, step) = linear_ticks(lo, hi, target);
        let fmt = NumFormat::new(&vals, step);
        vals.into_iter()
            .map(|v| Tick {
                t: v,
                major: true,
                label: Label::Text(fmt.format(v)),
            })
            .collect()
    }
}

/// Decade ticks for a log axis whose transformed range is `[lo, hi]`
/// (exponents). At most about `max_labels` decades are labelled; minor ticks
/// 2..9 are added when a decade spans at least 30 px. Ranges containing fewer
/// than two decades fall back to nice linear ticks.
fn log_ticks(lo: f64, hi: f64, max_labels: f64, decade_px: f64) -> Vec<Tick> {
    let e0 = (lo - 1e-9).ceil();
    let e1 = (hi + 1e-9).floor();
    if !(e0.is_finite() && e1.is_finite()) || e1 - e0 > 2000.0 {
        return Vec::new();
    }
    let (e0, e1) = (e0 as i32, e1 as i32);
    let n = e1 - e0 + 1;
    if n < 2 {
        let (vals, step) = linear_ticks(pow10_f(lo), pow10_f(hi), 4.0);
        let vals: Vec<f64> = vals.into_iter().filter(|&v| v > 0.0).collect();
        let fmt = NumFormat::new(&vals, step);
        return vals
            .into_iter()
            .map(|v| Tick {
                t: v.log10(),
                major: true,
                label: Label::Text(fmt.format(v)),
            })
            .collect();
    }
    // With only two decades of moderate magnitude, label 1, 2, 5 × 10^k as
    // plain numbers (e.g. 5, 10, 20, 50) so that the axis is readable.
    let plain = n <= 2 && lo >= -3.0 - 1e-9 && hi <= 5.0 + 1e-9;
    let step = ((f64::from(n) / max_labels.max(2.0)).ceil() as i32).max(1);
    let minors = step == 1 && (decade_px >= 30.0 || plain);
    let mut ticks = Vec::new();
    for e in (e0 - 1)..=e1 {
        if e >= e0 {
            let major = e.rem_euclid(step) == 0;
            let label = match (major, plain) {
                (false, _) => Label::None,
                (true, false) => Label::Pow10(e),
                (true, true) => Label::Text(plain_decimal(1, e)),
            };
            ticks.push(Tick {
                t: f64::from(e),
                major,
                label,
            });
        }
        if minors {
            for m in 2..=9 {
                let t = f64::from(e) + f64::from(m).log10();
                if t >= lo && t <= hi {
                    let major = plain && (m == 2 || m == 5);
                    ticks.push(Tick {
                        t,
                        major,
                        label: if major {
                            Label::Text(plain_decimal(m, e))
                        } else {
                            Label::None
                        },
                    });
                }
            }
        }
    }
    ticks
}

/// `m × 10^e` written as a plain decimal number (`m` a single digit).
fn plain_decimal(m: u32, e: i32) -> String {
    if e >= 0 {
        let mut s = m.to_string();
        s.extend(std::iter::repeat_n('0', e as usize));
        s
    } else {
        let zeros = (-e - 1) as usize;
        format!("0.{}{m}", "0".repeat(zeros))
    }
}

/// 10^t for a real exponent.
fn pow10_f(t: f64) -> f64 {
    10f64.powf(t)
}

/// Compact formatting of the tick values of one axis: fixed decimals (as
/// many as the step needs) for moderate magnitudes, otherwise `m.me±k` with
/// trailing zeros of the mantissa removed (e.g. `2e−6`, `1.5e6`).
#[derive(Debug, Clone, Copy)]
struct NumFormat {
    sci: bool,
    step_exp: i32,
    step: f64,
}

impl NumFormat {
    fn new(vals: &[f64], step: f64) -> Self {
        let max_abs = vals.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let step_exp = if step > 0.0 {
            (step.log10() + 1e-9).floor() as i32
        } else {
            0
        };
        NumFormat {
            sci: max_abs > 0.0 && !(1e-3..1e5).contains(&max_abs),
            step_exp,
            step,
        }
    }

    fn format(&self, v: f64) -> String {
        if v == 0.0 || v.abs() < self.step * 1e-6 {
            return "0".to_string();
        }
        let s = if self.sci {
            let e = (v.abs().log10() + 1e-9).floor() as i32;
            let decimals = (e - self.step_exp).clamp(0, 12) as usize;
            let m = format!("{:.*}", decimals, v / pow10(e));
            let m = if m.contains('.') {
                m.trim_end_matches('0').trim_end_matches('.')
            } else {
                &m
            };
            format!("{m}e{e}")
        } else {
            let decimals = (-self.step_exp).clamp(0, 12) as usize;
            format!("{:.*}", decimals, v)
        };
        minus(&s)
    }
}

/// Replaces ASCII hyphens by the typographic minus sign U+2212.
fn minus(s: &str) -> String {
    s.replace('-', "\u{2212}")
}

fn text_width(s: &str, font: f64) -> f64 {
    s.chars().count() as f64 * font * CHAR_W
}

/// Formats a pixel coordinate rounded to 0.1 px, without a trailing ".0".
fn num(v: f64) -> String {
    let r = (v * 10.0).round() / 10.0;
    if r == 0.0 || !r.is_finite() {
        return "0".to_string();
    }
    let s = format!("{r:.1}");
    match s.strip_suffix(".0") {
        Some(t) => t.to_string(),
        None => s,
    }
}

/// Escapes XML special characters and drops characters not allowed in XML 1.0.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {}
            c => out.push(c),
        }
    }
    out
}

/// Pixel-space pieces of a series: split at undrawable points, decimated if
/// the series is long, rounded to 0.1 px with consecutive duplicates removed.
fn series_pieces(s: &Series, lay: &Layout) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for &(x, y) in &s.points {
        match (lay.x.map(x), lay.y.map(y)) {
            (Some(px), Some(py)) => cur.push((px, py)),
            _ => {
                if !cur.is_empty() {
                    pieces.push(std::mem::take(&mut cur));
                }
            }
        }
    }
    if !cur.is_empty() {
        pieces.push(cur);
    }
    let total: usize = pieces.iter().map(Vec::len).sum();
    let decimate = total > DECIMATE_THRESHOLD;
    pieces
        .into_iter()
        .map(|p| {
            let p = if decimate { decimate_columns(&p) } else { p };
            let mut out: Vec<(f64, f64)> = Vec::with_capacity(p.len());
            for (x, y) in p {
                let q = ((x * 10.0).round() / 10.0, (y * 10.0).round() / 10.0);
                if out.last() != Some(&q) {
                    out.push(q);
                }
            }
            out
        })
        .collect()
}

/// Keeps, for every run of consecutive points falling in the same pixel
/// column, the first, lowest, highest and last point (in their original
/// order). For monotonic x this is min/max per column, which preserves the
/// drawn envelope while bounding the output to ~4 points per column.
fn decimate_columns(p: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < p.len() {
        let col = p[i].0.floor();
        let (mut imin, mut imax) = (i, i);
        let mut j = i + 1;
        while j < p.len() && p[j].0.floor() == col {
            if p[j].1 < p[imin].1 {
                imin = j;
            }
            if p[j].1 > p[imax].1 {
                imax = j;
            }
            j += 1;
        }
        let mut idx = [i, imin, imax, j - 1];
        idx.sort_unstable();
        let mut prev = usize::MAX;
        for k in idx {
            if k != prev {
                out.push(p[k]);
                prev = k;
            }
        }
        i = j;
    }
    out
}

fn dash_attr(style: Style) -> &'static str {
    if style == Style::Dashed {
        " stroke-dasharray=\"6 4\""
    } else {
        ""
    }
}

fn write_series(out: &mut String, index: usize, style: Style, pieces: &[Vec<(f64, f64)>]) {
    let color = PALETTE[index % PALETTE.len()];
    let line = style != Style::Markers;
    let markers = matches!(style, Style::Markers | Style::LineMarkers);
    if line {
        let _ = writeln!(
            out,
            "<g fill=\"none\" stroke=\"{color}\" stroke-width=\"{}\" stroke-linejoin=\"round\" \
             stroke-linecap=\"round\"{}>",
            num(LINE_WIDTH),
            dash_attr(style)
        );
        for p in pieces {
            if p.len() >= 2 {
                out.push_str("<polyline points=\"");
                for (k, &(x, y)) in p.iter().enumerate() {
                    if k > 0 {
                        out.push(' ');
                    }
                    let _ = write!(out, "{},{}", num(x), num(y));
                }
                out.push_str("\"/>\n");
            } else if let (Some(&(x, y)), false) = (p.first(), markers) {
                // An isolated point would be invisible as a line: draw a dot.
                let _ = writeln!(
                    out,
                    "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{color}\" stroke=\"none\"/>",
                    num(x),
                    num(y),
                    num(LINE_WIDTH)
                );
            }
        }
        out.push_str("</g>\n");
    }
    if markers {
        let mut d = String::new();
        for p in pieces {
            for &pt in p {
                marker_path(&mut d, index, pt);
            }
        }
        if !d.is_empty() {
            let _ = writeln!(out, "<path d=\"{d}\" fill=\"{color}\"/>");
        }
    }
}

/// Appends a filled marker shape (depending on the series index) at `(x, y)`.
fn marker_path(d: &mut String, index: usize, (x, y): (f64, f64)) {
    let r = MARKER_R;
    let _ = match index % 5 {
        // circle
        0 => write!(
            d,
            "M{} {}a{r} {r} 0 1 0 {} 0a{r} {r} 0 1 0 {} 0z",
            num(x - r),
            num(y),
            num(2.0 * r),
            num(-2.0 * r)
        ),
        // square
        1 => {
            let a = r * 0.85;
            write!(
                d,
                "M{} {}h{}v{}h{}z",
                num(x - a),
                num(y - a),
                num(2.0 * a),
                num(2.0 * a),
                num(-2.0 * a)
            )
        }
        // triangle up
        2 => write!(
            d,
            "M{} {}l{} {}h{}z",
            num(x),
            num(y - 1.2 * r),
            num(1.1 * r),
            num(2.0 * r),
            num(-2.2 * r)
        ),
        // diamond
        3 => write!(
            d,
            "M{} {}l{} {}l{} {}l{} {}z",
            num(x),
            num(y - 1.25 * r),
            num(r),
            num(1.25 * r),
            num(-r),
            num(1.25 * r),
            num(-r),
            num(-1.25 * r)
        ),
        // triangle down
        _ => write!(
            d,
            "M{} {}l{} {}h{}z",
            num(x),
            num(y + 1.2 * r),
            num(1.1 * r),
            num(-2.0 * r),
            num(-2.2 * r)
        ),
    };
}

#[derive(Debug, Clone, Copy)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Rect {
    fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    fn contains(&self, (x, y): (f64, f64)) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// Liang–Barsky test: does the segment `a`–`b` touch the rectangle?
    fn hits_segment(&self, a: (f64, f64), b: (f64, f64)) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let mut t0: f64 = 0.0;
        let mut t1: f64 = 1.0;
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

/// Number of drawn segments / markers of a series overlapping `rect`.
fn count_hits(style: Style, pieces: &[Vec<(f64, f64)>], rect: &Rect) -> usize {
    let mut n = 0;
    for p in pieces {
        if style == Style::Markers || p.len() == 1 {
            n += p.iter().filter(|&&q| rect.contains(q)).count();
        } else {
            n += p
                .windows(2)
                .filter(|w| rect.hits_segment(w[0], w[1]))
                .count();
        }
    }
    n
}

/// Renders an SVG document (as written by [`Chart::to_svg`]) to a PNG file at 1.5 times its
/// size, on white, with the system's fonts (DejaVu Sans for `sans-serif` when present),
/// written whole or not at all ([`crate::outputs::write_atomically`]).
pub fn write_png(svg: &str, path: &std::path::Path) -> Result<(), String> {
    let bytes = png_bytes(svg)?;
    crate::outputs::write_atomically(path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The PNG bytes of [`write_png`].
fn png_bytes(svg: &str) -> Result<Vec<u8>, String> {
    use resvg::{tiny_skia, usvg};
    let mut options = usvg::Options::default();
    {
        let db = options.fontdb_mut();
        db.load_system_fonts();
        if db
            .faces()
            .any(|f| f.families.iter().any(|(n, _)| n == "DejaVu Sans"))
        {
            db.set_sans_serif_family("DejaVu Sans");
        }
    }
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| format!("SVG: {e}"))?;
    let scale = 1.5;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or("empty chart")?;
    let mut pixmap =
        tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("chart too large")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap.encode_png().map_err(|e| format!("PNG: {e}"))
}

/// Writes `chart` as `<stem>.svg` (900 × 600) and `<stem>.png` (1350 × 900 px), each under a temporary name
/// renamed when complete, and returns both paths.
pub fn svg_and_png(
    chart: &Chart,
    stem: &std::path::Path,
) -> Result<Vec<std::path::PathBuf>, String> {
    svg_and_png_as(chart, &[stem])
}

/// Like [`svg_and_png`], under each of `stems` (the chart is drawn and rasterised once; every
/// copy is the same bytes): `<stem>.svg` and `<stem>.png` for each stem in order, each written
/// under a temporary name and renamed when complete. Returns the paths in that order.
pub fn svg_and_png_as(
    chart: &Chart,
    stems: &[&std::path::Path],
) -> Result<Vec<std::path::PathBuf>, String> {
    let Some((first, rest)) = stems.split_first() else {
        return Ok(Vec::new());
    };
    let svg = chart.to_svg(900, 600);
    let png =
        png_bytes(&svg).map_err(|e| format!("{}: {e}", first.with_extension("png").display()))?;
    let mut written = Vec::new();
    for stem in std::iter::once(first).chain(rest) {
        for (path, bytes) in [
            (stem.with_extension("svg"), svg.as_bytes()),
            (stem.with_extension("png"), png.as_slice()),
        ] {
            crate::outputs::write_atomically(&path, bytes)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            written.push(path);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Minimal XML well-formedness checker: balanced and properly nested
    /// tags, a single root element, quoted unique attributes, no stray `<`,
    /// and only predefined or numeric entities.
    fn check_xml(s: &str) -> Result<(), String> {
        let b = s.as_bytes();
        let mut stack: Vec<&str> = Vec::new();
        let mut root_done = false;
        let mut i = 0;
        while i < b.len() {
            match b[i] {
                b'<' => {
                    if s[i..].starts_with("<!--") {
                        i += s[i..].find("-->").ok_or("open comment")? + 3;
                        continue;
                    }
                    let end = i + s[i..].find('>').ok_or("unterminated tag")?;
                    let tag = &s[i + 1..end];
                    if tag.contains('<') {
                        return Err(format!("'<' inside tag at {i}"));
                    }
                    if let Some(name) = tag.strip_prefix('/') {
                        let open = stack.pop().ok_or("close without open")?;
                        if open != name.trim() {
                            return Err(format!("mismatched </{name}> for <{open}>"));
                        }
                        if stack.is_empty() {
                            root_done = true;
                        }
                    } else {
                        let self_closing = tag.ends_with('/');
                        let body = tag.strip_suffix('/').unwrap_or(tag);
                        let name_end = body.find(|c: char| c.is_whitespace()).unwrap_or(body.len());
                        let name = &body[..name_end];
                        if name.is_empty() {
                            return Err(format!("empty tag name at {i}"));
                        }
                        check_attrs(&body[name_end..])?;
                        if stack.is_empty() && root_done {
                            return Err("second root element".into());
                        }
                        if self_closing {
                            if stack.is_empty() {
                                root_done = true;
                            }
                        } else {
                            stack.push(name);
                        }
                    }
                    i = end + 1;
                }
                b'&' => {
                    let rest = &s[i..];
                    let ok = ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;", "&#"]
                        .iter()
                        .any(|e| rest.starts_with(e));
                    if !ok {
                        return Err(format!("bad entity at {i}"));
                    }
                    i += 1;
                }
                c => {
                    if stack.is_empty() && !c.is_ascii_whitespace() {
                        return Err(format!("text outside root at {i}"));
                    }
                    i += 1;
                }
            }
        }
        if !stack.is_empty() {
            return Err(format!("unclosed {stack:?}"));
        }
        if !root_done {
            return Err("no root".into());
        }
        Ok(())
    }

    fn check_attrs(mut a: &str) -> Result<(), String> {
        let mut names: Vec<&str> = Vec::new();
        loop {
            a = a.trim_start();
            if a.is_empty() {
                return Ok(());
            }
            let eq = a
                .find('=')
                .ok_or_else(|| format!("attribute without value: {a}"))?;
            let name = a[..eq].trim();
            if name.is_empty() || name.contains(char::is_whitespace) || names.contains(&name) {
                return Err(format!("bad or duplicate attribute name '{name}'"));
            }
            names.push(name);
            let rest = a[eq + 1..].trim_start();
            let rest = rest
                .strip_prefix('"')
                .ok_or_else(|| format!("unquoted attribute {name}"))?;
            let close = rest.find('"').ok_or("unterminated attribute")?;
            a = &rest[close + 1..];
        }
    }

    /// All points of all `<polyline>` elements, one vector per polyline.
    fn polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
        svg.split("<polyline points=\"")
            .skip(1)
            .map(|chunk| {
                let pts = &chunk[..chunk.find('"').unwrap()];
                pts.split(' ')
                    .map(|pair| {
                        let (x, y) = pair.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect()
            })
            .collect()
    }

    fn sample_chart() -> Chart {
        let mut c = Chart::new("Nutation angle", "time [s]", "angle [deg]");
        c.series.push(Series::new(
            "rigid",
            (0..200)
                .map(|i| (i as f64, (i as f64 * 0.1).sin()))
                .collect(),
            Style::Line,
        ));
        c.series.push(Series::new(
            "flexible",
            (0..20)
                .map(|i| (i as f64 * 10.0, (i as f64).cos()))
                .collect(),
            Style::LineMarkers,
        ));
        c.reference_lines
            .push(ReferenceLine::new(Axis::Y, 0.5, "limit"));
        c
    }

    #[test]
    fn well_formed_and_standalone() {
        let svg = sample_chart().to_svg(640, 400);
        check_xml(&svg).unwrap();
        assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
        assert!(svg.contains("viewBox=\"0 0 640 400\""));
        assert!(svg.contains("width=\"640\" height=\"400\""));
        assert!(svg.contains("font-family=\"sans-serif\""));
        assert!(svg.contains("stroke-dasharray=\"5 4\"")); // reference line
        assert!(svg.contains(">limit</text>"));
        assert!(svg.contains(">rigid</text>") && svg.contains(">flexible</text>"));
        assert!(svg.contains(PALETTE[0]) && svg.contains(PALETTE[1]));
    }

    #[test]
    fn checker_rejects_bad_xml() {
        assert!(check_xml("<svg><g></svg>").is_err());
        assert!(check_xml("<svg a=\"1\" a=\"2\"/>").is_err());
        assert!(check_xml("<svg>a & b</svg>").is_err());
        assert!(check_xml("<svg/><svg/>").is_err());
        assert!(check_xml("<svg><g/>x &amp; y</svg>").is_ok());
    }

    #[test]
    fn escapes_all_text() {
        let mut c = Chart::new("a<b & \"c\" 'd'", "x>0", "y&z");
        c.series.push(Series::new(
            "<script>",
            vec![(0.0, 1.0), (1.0, 2.0)],
            Style::Line,
        ));
        c.reference_lines
            .push(ReferenceLine::new(Axis::X, 0.5, "t<sub>0</sub>"));
        let svg = c.to_svg(500, 300);
        check_xml(&svg).unwrap();
        assert!(svg.contains("a&lt;b &amp; &quot;c&quot; &apos;d&apos;"));
        assert!(svg.contains("x&gt;0"));
        assert!(svg.contains("y&amp;z"));
        assert!(svg.contains("&lt;script&gt;"));
        assert!(svg.contains("t&lt;sub&gt;0&lt;/sub&gt;"));
        assert!(!svg.contains("<script>") && !svg.contains("<sub>"));
        assert_eq!(escape("a\u{1}b\nc"), "ab c");
    }

    #[test]
    fn log_ticks_are_decades() {
        let ticks = log_ticks(-12.0, -3.0, 20.0, 40.0);
        let majors: Vec<i32> = ticks
            .iter()
            .filter(|t| t.major)
            .map(|t| match t.label {
                Label::Pow10(e) => e,
                _ => panic!("major log tick without decade label"),
            })
            .collect();
        assert_eq!(majors, (-12..=-3).collect::<Vec<_>>());
        for t in ticks.iter().filter(|t| t.major) {
            assert_eq!(t.t, t.t.round());
        }
        // Minor ticks at 2..9 × 10^k, none outside the range.
        assert!(
            ticks
                .iter()
                .any(|t| !t.major && (t.t - (-12.0 + 2f64.log10())).abs() < 1e-12)
        );
        assert!(
            ticks
                .iter()
                .all(|t| t.t >= -12.0 - 1e-9 && t.t <= -3.0 + 1e-9)
        );

        // Through the chart: a log y axis from 1e-12 to 1e-3.
        let mut c = Chart::new("", "", "");
        c.y_scale = Scale::Log10;
        c.y_range = Some((1e-12, 1e-3));
        let lay = c.layout(640.0, 600.0);
        let majors: Vec<&Tick> = lay.y_ticks.iter().filter(|t| t.major).collect();
        assert!(majors.len() >= 5);
        assert!(majors.iter().all(|t| matches!(t.label, Label::Pow10(_))));
        let svg = c.to_svg(640, 600);
        check_xml(&svg).unwrap();
        assert!(svg.contains("10<tspan dy=\"-0.5em\" font-size=\"8.3\">\u{2212}12</tspan>"));

        // Many decades on a short axis are thinned but stay decades.
        let thin = log_ticks(-300.0, 300.0, 6.0, 1.0);
        let labelled = thin.iter().filter(|t| t.major).count();
        assert!((4..=8).contains(&labelled), "{labelled}");
    }

    #[test]
    fn log_ticks_two_decades_use_plain_labels() {
        let labels: Vec<String> = log_ticks(3f64.log10(), 2.1, 6.0, 100.0)
            .into_iter()
            .filter_map(|t| match t.label {
                Label::Text(s) => Some(s),
                Label::None => None,
                Label::Pow10(e) => panic!("unexpected 10^{e}"),
            })
            .collect();
        assert_eq!(labels, ["5", "10", "20", "50", "100"]);
        assert_eq!(plain_decimal(2, -3), "0.002");
        assert_eq!(plain_decimal(5, 2), "500");
    }

    #[test]
    fn log_ticks_narrow_range_falls_back_to_linear() {
        let ticks = log_ticks(2f64.log10(), 9f64.log10(), 6.0, 200.0);
        let labels: Vec<String> = ticks
            .iter()
            .map(|t| match &t.label {
                Label::Text(s) => s.clone(),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(labels, ["2", "4", "6", "8"]);
    }

    #[test]
    fn linear_ticks_nice() {
        let (ticks, step) = linear_ticks(0.0, 93.0, 5.0);
        assert_eq!(step, 20.0);
        assert_eq!(ticks, vec![0.0, 20.0, 40.0, 60.0, 80.0]);

        let (ticks, step) = linear_ticks(-0.3, 1.2, 6.0);
        let fmt = NumFormat::new(&ticks, step);
        let labels: Vec<String> = ticks.iter().map(|&v| fmt.format(v)).collect();
        assert_eq!(
            labels,
            ["\u{2212}0.2", "0", "0.2", "0.4", "0.6", "0.8", "1.0", "1.2"]
        );

        let (ticks, step) = linear_ticks(0.0, 1e-5, 5.0);
        let fmt = NumFormat::new(&ticks, step);
        assert_eq!(fmt.format(ticks[1]), "2e\u{2212}6");
        assert_eq!(fmt.format(0.0), "0");

        let (ticks, step) = linear_ticks(0.0, 1.0, 2.0);
        let fmt = NumFormat::new(&ticks, step);
        assert_eq!(fmt.format(ticks[1]), "0.5");

        let (ticks, step) = linear_ticks(0.0, 3e6, 3.0);
        let fmt = NumFormat::new(&ticks, step);
        assert_eq!(fmt.format(ticks[1]), "1e6");
    }

    #[test]
    fn nan_gap_splits_polyline() {
        let mut c = Chart::new("gap", "x", "y");
        c.series.push(Series::new(
            "s",
            vec![
                (0.0, 0.0),
                (1.0, 1.0),
                (2.0, f64::NAN),
                (3.0, 1.0),
                (f64::INFINITY, 2.0),
                (4.0, 0.0),
                (5.0, 1.0),
            ],
            Style::Line,
        ));
        let svg = c.to_svg(400, 300);
        check_xml(&svg).unwrap();
        assert_eq!(polylines(&svg).len(), 2);
        // The isolated point (3, 1) between two gaps is drawn as a dot.
        assert_eq!(svg.matches("<circle").count(), 1);
    }

    #[test]
    fn log_axis_skips_non_positive() {
        let mut c = Chart::new("", "", "");
        c.y_scale = Scale::Log10;
        c.series.push(Series::new(
            "s",
            vec![
                (0.0, 1.0),
                (1.0, 10.0),
                (2.0, 0.0),
                (3.0, 100.0),
                (4.0, 1000.0),
            ],
            Style::Dashed,
        ));
        let lay = c.layout(400.0, 300.0);
        assert!(lay.y.lo < 0.0 && lay.y.hi > 3.0);
        let svg = c.to_svg(400, 300);
        check_xml(&svg).unwrap();
        assert_eq!(polylines(&svg).len(), 2);
        assert!(svg.contains("stroke-dasharray=\"6 4\""));
    }

    #[test]
    fn decimation_bounds_size_and_keeps_envelope() {
        let n = 1_000_000;
        let mut state: u64 = 12345;
        let mut pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let t = i as f64 * 1e-3;
                (t, (t * 0.05).sin() + 0.2 * noise)
            })
            .collect();
        pts[123_457].1 = 3.0; // single-sample spike up
        pts[654_321].1 = -2.5; // single-sample spike down
        let mut c = Chart::new("big", "t", "y");
        c.series.push(Series::new("noisy", pts, Style::Line));
        let svg = c.to_svg(800, 500);
        assert!(svg.len() < 200_000, "{} bytes", svg.len());
        check_xml(&svg).unwrap();

        let lay = c.layout(800.0, 500.0);
        let drawn: Vec<(f64, f64)> = polylines(&svg).into_iter().flatten().collect();
        let top = drawn.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let bot = drawn.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        let want_top = lay.y.map(3.0).unwrap();
        let want_bot = lay.y.map(-2.5).unwrap();
        assert!((top - want_top).abs() <= 0.051, "{top} vs {want_top}");
        assert!((bot - want_bot).abs() <= 0.051, "{bot} vs {want_bot}");
        // The spikes are at the right place horizontally too.
        let spike_x = lay.x.map(123.457).unwrap();
        assert!(
            drawn
                .iter()
                .any(|p| (p.1 - top).abs() < 0.01 && (p.0 - spike_x).abs() <= 0.06)
        );
    }

    #[test]
    fn decimation_keeps_first_last_and_extremes() {
        let p: Vec<(f64, f64)> = (0..100)
            .map(|i| (0.5 + i as f64 * 1e-3, (i % 7) as f64))
            .collect();
        let d = decimate_columns(&p);
        assert!(d.len() <= 4);
        assert_eq!(d[0], p[0]);
        assert_eq!(*d.last().unwrap(), p[99]);
        assert!(d.iter().any(|q| q.1 == 6.0) && d.iter().any(|q| q.1 == 0.0));
    }

    #[test]
    fn empty_chart_is_valid() {
        let svg = Chart::new("Empty", "x", "y").to_svg(400, 300);
        check_xml(&svg).unwrap();
        assert!(!svg.contains("<polyline"));
        assert!(svg.contains(">Empty</text>"));

        let mut c = Chart::new("", "", "");
        c.x_scale = Scale::Log10;
        c.y_scale = Scale::Log10;
        check_xml(&c.to_svg(300, 200)).unwrap();
        // Tiny sizes must not panic and stay well-formed.
        check_xml(&sample_chart().to_svg(0, 0)).unwrap();
        check_xml(&sample_chart().to_svg(20, 10)).unwrap();
    }

    #[test]
    fn degenerate_ranges_still_draw() {
        let mut c = Chart::new("flat", "x", "y");
        c.series.push(Series::new(
            "const",
            vec![(1.0, 5.0), (2.0, 5.0), (3.0, 5.0)],
            Style::Line,
        ));
        let lay = c.layout(400.0, 300.0);
        assert!(lay.y.lo < 5.0 && lay.y.hi > 5.0);
        let svg = c.to_svg(400, 300);
        check_xml(&svg).unwrap();
        assert_eq!(polylines(&svg).len(), 1);

        // A single point: both ranges degenerate.
        let mut c = Chart::new("", "", "");
        c.x_scale = Scale::Log10;
        c.series.push(Series::new(
            "one",
            vec![(0.0, 0.0), (7.0, 0.0)],
            Style::Markers,
        ));
        let svg = c.to_svg(400, 300);
        check_xml(&svg).unwrap();
        assert!(svg.contains("<path d=\"M"));
    }

    #[test]
    fn fixed_ranges_and_reference_lines() {
        let mut c = sample_chart();
        c.x_range = Some((50.0, 100.0));
        c.reference_lines
            .push(ReferenceLine::new(Axis::X, 1000.0, "outside"));
        let lay = c.layout(640.0, 400.0);
        assert_eq!((lay.x.lo, lay.x.hi), (50.0, 100.0));
        let svg = c.to_svg(640, 400);
        check_xml(&svg).unwrap();
        assert!(!svg.contains("outside"));
        // An invalid fixed log range falls back to the data.
        c.y_scale = Scale::Log10;
        c.y_range = Some((-1.0, 1.0));
        check_xml(&c.to_svg(640, 400)).unwrap();
    }

    #[test]
    fn number_formatting() {
        assert_eq!(num(1.25), "1.3");
        assert_eq!(num(-0.04), "0");
        assert_eq!(num(12.0), "12");
        assert_eq!(num(-3.46), "-3.5");
    }
}
