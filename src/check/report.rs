//! The human-readable form of a [`CheckReport`]: one line per measure, the worst element named.

use super::{CheckReport, Location, Measure};
use std::fmt;

fn verdict(ok: bool) -> &'static str {
    if ok {
        "ok"
    } else {
        "FAIL"
    }
}

fn fmt_location(at: &Option<Location>) -> String {
    fmt_location_as("worst", at)
}

fn fmt_location_as(label: &str, at: &Option<Location>) -> String {
    let Some(at) = at else {
        return String::new();
    };
    let patches = at
        .patches
        .iter()
        .zip(&at.elements)
        .map(|(p, e)| format!("{p} ({e})"))
        .collect::<Vec<_>>()
        .join(", ");
    let vertex = at
        .vertex
        .map(|v| format!("vertex {v}, "))
        .unwrap_or_default();
    let [x, y, z] = at.point;
    let noun = if at.patches.len() == 1 {
        "patch"
    } else {
        "patches"
    };
    format!("  ({label}: {vertex}{noun} {patches} at ({x:.6}, {y:.6}, {z:.6}))")
}

fn measure_line(
    f: &mut fmt::Formatter<'_>,
    name: &str,
    m: &Measure,
    tol: f64,
    judged: bool,
) -> fmt::Result {
    let v = if judged {
        verdict(m.within(tol))
    } else {
        "info"
    };
    writeln!(
        f,
        "{name:<16} {:>10.3e}  (tolerance {tol:.0e}, {} samples)  {v}{}",
        m.worst,
        m.samples,
        fmt_location(&m.at)
    )
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let o = &self.options;
        writeln!(
            f,
            "scheme {} (C{} promised), {} patches, {} vertices",
            self.scheme, self.continuity, self.patches, self.vertices
        )?;
        if self.invalid_patches > 0 {
            writeln!(
                f,
                "invalid patches  {} not measured  FAIL  (first: {})",
                self.invalid_patches,
                self.first_invalid.as_deref().unwrap_or("")
            )?;
        }
        let fs = &self.faces;
        writeln!(
            f,
            "faces            {} shared, {} boundary, {} shared by more than two  {}{}",
            fs.shared,
            fs.boundary,
            fs.overshared,
            verdict(fs.overshared == 0),
            fmt_location_as("e.g.", &fs.overshared_at)
        )?;
        writeln!(
            f,
            "t-junctions      {} overlapping boundary face pairs  {}{}",
            fs.t_junctions,
            verdict(fs.t_junctions == 0),
            fmt_location_as("e.g.", &fs.t_junction_at)
        )?;
        measure_line(f, "value jump", &self.value_jump, o.jump_tolerance, true)?;
        measure_line(
            f,
            "gradient jump",
            &self.gradient_jump,
            o.jump_tolerance,
            true,
        )?;
        measure_line(
            f,
            "hessian jump",
            &self.hessian_jump,
            o.hessian_tolerance,
            self.continuity >= 2,
        )?;
        let it = &self.interpolation;
        measure_line(f, "vertex value", &it.value, o.value_tolerance, true)?;
        measure_line(
            f,
            "vertex normal",
            &it.normal_angle,
            o.angle_tolerance,
            true,
        )?;
        if it.off_corner > 0 || it.outside > 0 {
            writeln!(
                f,
                "vertex location  {} not at a tetrahedron corner, {} outside every tetrahedron  {}",
                it.off_corner,
                it.outside,
                verdict(it.outside == 0)
            )?;
        }
        let s = &self.sheets;
        writeln!(
            f,
            "shooting roots   {} non-simple of {} lines in {} patches, smallest slope {} \
             (tolerance {:.0e})  {}{}",
            s.non_simple,
            s.shooting_lines,
            s.shooting_patches,
            s.min_root_slope
                .map_or_else(|| "-".to_string(), |v| format!("{v:.3e}")),
            o.simple_root_tolerance,
            verdict(s.non_simple == 0),
            fmt_location(&s.min_root_slope_at)
        )?;
        let multi_verdict = if o.single_sheet {
            verdict(s.multi_sheet_patches == 0)
        } else if s.multi_sheet_patches > 0 {
            "warning"
        } else {
            "ok"
        };
        writeln!(
            f,
            "sheets           {} patches crossed twice from every vertex ({} of {} vertex lines \
             cross F = 0 more than once)  {}{}",
            s.multi_sheet_patches,
            s.multi_root_lines,
            s.vertex_lines,
            multi_verdict,
            fmt_location_as(
                "e.g.",
                &s.multi_sheet_at.clone().or(s.multi_root_at.clone())
            )
        )?;
        if s.j_patches > 0 {
            writeln!(
                f,
                "j-sheets         {} of {} patches with a j-vertex/j-edge crossed twice ({} of {} \
                 lines)  {}{}",
                s.j_multi_patches,
                s.j_patches,
                s.j_multi_lines,
                s.j_lines,
                verdict(s.j_multi_lines == 0),
                fmt_location_as("e.g.", &s.j_multi_at)
            )?;
        }
        let h = &self.holes;
        if h.boundary_faces > 0 {
            writeln!(
                f,
                "holes            {} of {} boundary faces crossed by the surface{} (depth {:.3e}), \
                 {} certified one-signed, {} uncertified  {}{}",
                h.crossing,
                h.boundary_faces,
                if h.crossing_by_role.is_empty() {
                    String::new()
                } else {
                    let roles: Vec<String> = h
                        .crossing_by_role
                        .iter()
                        .map(|(r, n)| format!("{n} {r}"))
                        .collect();
                    format!(" ({})", roles.join(", "))
                },
                h.worst,
                h.certified,
                h.uncertified,
                verdict(h.crossing == 0),
                fmt_location_as("worst", &h.crossing_at)
            )?;
            if !h.crossing_by_cause.is_empty() {
                let causes: Vec<String> = h
                    .crossing_by_cause
                    .iter()
                    .map(|(c, n)| format!("{n} {c}"))
                    .collect();
                writeln!(
                    f,
                    "                 held by (the coefficient most against the face's sign): {}",
                    causes.join(", ")
                )?;
            }
        }
        let failures = self.failures();
        if failures.is_empty() {
            writeln!(f, "PASSED")
        } else {
            writeln!(f, "FAILED: {}", failures.join(", "))
        }
    }
}
