//! The two histograms the paper shows for a mesh (scaled Jacobian min J / max J and
//! equiangular skewness), drawn as a self-contained SVG. Hand-written: two bar charts
//! are a few dozen lines, not worth a plotting dependency.

use super::report::QualityReport;
use crate::geom::tet_quality::Histogram;
use std::fmt::Write;

const W: f64 = 960.0;
const H: f64 = 440.0;
const PANEL_W: f64 = 400.0;
const PANEL_H: f64 = 260.0;
const TOP: f64 = 105.0;

/// Escape text for SVG.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A "nice" upper end for a percentage axis.
fn nice_max(p: f64) -> f64 {
    for m in [
        1.0, 2.0, 5.0, 10.0, 20.0, 25.0, 40.0, 50.0, 60.0, 80.0, 100.0,
    ] {
        if p <= m {
            return m;
        }
    }
    100.0
}

/// One panel: `fill` bars, optional `outline` bars (same bins), vertical markers.
#[allow(clippy::too_many_arguments)]
fn panel(
    out: &mut String,
    x0: f64,
    title: &str,
    subtitle: &str,
    fill: &Histogram,
    outline: Option<&Histogram>,
    colour: &str,
    markers: &[(f64, usize)],
) {
    let total = fill.total().max(1) as f64;
    let pct = |h: &Histogram, i: usize| 100.0 * h.counts[i] as f64 / h.total().max(1) as f64;
    let mut top = 0.0f64;
    for i in 0..fill.counts.len() {
        top = top.max(pct(fill, i));
        if let Some(o) = outline {
            top = top.max(pct(o, i));
        }
    }
    let ymax = nice_max(top.max(1e-9));
    let (lo, hi) = (fill.lo, fill.hi);
    let sx = |v: f64| x0 + (v - lo) / (hi - lo) * PANEL_W;
    let sy = |p: f64| TOP + PANEL_H - p / ymax * PANEL_H;
    let _ = writeln!(
        out,
        r#"<text x="{:.1}" y="{:.1}" font-size="16" font-weight="bold" text-anchor="middle">{}</text>"#,
        x0 + PANEL_W / 2.0,
        TOP - 48.0,
        esc(title)
    );
    let _ = writeln!(
        out,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" fill="#444">{}</text>"##,
        x0 + PANEL_W / 2.0,
        TOP - 28.0,
        esc(subtitle)
    );
    // Grid and y axis.
    for k in 0..=4 {
        let p = ymax * k as f64 / 4.0;
        let y = sy(p);
        let _ = writeln!(
            out,
            r##"<line x1="{x0:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end">{p}%</text>"##,
            x0 + PANEL_W,
            x0 - 6.0,
            y + 4.0
        );
    }
    // Bars.
    let nb = fill.counts.len();
    let bw = PANEL_W / nb as f64;
    for i in 0..nb {
        let p = pct(fill, i);
        if fill.counts[i] > 0 {
            let (x, y) = (x0 + i as f64 * bw, sy(p));
            let _ = writeln!(
                out,
                r#"<rect x="{:.1}" y="{y:.1}" width="{:.1}" height="{:.1}" fill="{colour}" fill-opacity="0.8"><title>{}: {} ({p:.2}%)</title></rect>"#,
                x + 1.0,
                bw - 2.0,
                TOP + PANEL_H - y,
                esc(&format!(
                    "[{:.2}, {:.2})",
                    lo + i as f64 * (hi - lo) / nb as f64,
                    lo + (i + 1) as f64 * (hi - lo) / nb as f64
                )),
                fill.counts[i]
            );
            let _ = writeln!(
                out,
                r#"<text x="{:.1}" y="{:.1}" font-size="9" text-anchor="middle">{}</text>"#,
                x + bw / 2.0,
                y - 3.0,
                fill.counts[i]
            );
        }
        if let Some(o) = outline {
            if o.counts[i] > 0 {
                let y = sy(pct(o, i));
                let _ = writeln!(
                    out,
                    r#"<rect x="{:.1}" y="{y:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="black" stroke-dasharray="3,2"/>"#,
                    x0 + i as f64 * bw + 1.0,
                    bw - 2.0,
                    TOP + PANEL_H - y
                );
            }
        }
    }
    for (k, &(m, n_above)) in markers.iter().enumerate() {
        let x = sx(m);
        let _ = writeln!(
            out,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#c00" stroke-dasharray="5,3"/><text x="{:.1}" y="{:.1}" font-size="10" fill="#c00" text-anchor="{}">&gt; {m}: {n_above}</text>"##,
            TOP,
            TOP + PANEL_H,
            if k % 2 == 0 { x - 3.0 } else { x + 3.0 },
            TOP + 12.0 + 12.0 * k as f64,
            if k % 2 == 0 { "end" } else { "start" }
        );
    }
    // x axis.
    let _ = writeln!(
        out,
        r#"<line x1="{x0:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="black"/>"#,
        TOP + PANEL_H,
        x0 + PANEL_W,
        TOP + PANEL_H
    );
    for k in 0..=4 {
        let v = lo + (hi - lo) * k as f64 / 4.0;
        let _ = writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" font-size="11" text-anchor="middle">{v}</text>"#,
            sx(v),
            TOP + PANEL_H + 16.0
        );
    }
    let outside = fill.below + fill.above + fill.nan;
    if outside > 0 {
        let _ = writeln!(
            out,
            r##"<text x="{:.1}" y="{:.1}" font-size="11" fill="#c00">{} below {lo}, {} above {hi}, {} NaN (of {total})</text>"##,
            x0,
            TOP + PANEL_H + 34.0,
            fill.below,
            fill.above,
            fill.nan
        );
    }
}

/// The SVG document: scaled Jacobian (sampled bars, certified lower bound dashed) and
/// equiangular skewness (markers at 0.85 and 0.9), in percent of the elements.
pub fn quality_svg(r: &QualityReport, title: &str) -> String {
    let q = &r.quality;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="22" font-size="14" text-anchor="middle">{} — {} tets, {} nodes, {} invalid</text>"#,
        W / 2.0,
        esc(title),
        r.num_tets,
        r.num_nodes,
        r.num_invalid
    );
    panel(
        &mut s,
        70.0,
        "Scaled Jacobian min J / max J",
        &format!(
            "min {:.3} (certified {:.3}), mean {:.3}; dashed: certified",
            q.scaled_jacobian.min, q.scaled_jacobian_certified.min, q.scaled_jacobian.mean
        ),
        &q.scaled_jacobian.histogram,
        Some(&q.scaled_jacobian_certified.histogram),
        "#3b6fb6",
        &[],
    );
    panel(
        &mut s,
        540.0,
        "Equiangular skewness",
        &format!(
            "max {:.3}, mean {:.3}; dihedral {:.1}°..{:.1}°",
            q.skewness.max, q.skewness.mean, q.min_dihedral.min, q.max_dihedral.max
        ),
        &q.skewness.histogram,
        None,
        "#d9822b",
        &[(0.85, r.skew_above_085), (0.9, r.skew_above_09)],
    );
    s.push_str("</svg>\n");
    s
}
