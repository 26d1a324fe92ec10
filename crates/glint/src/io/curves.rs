//! Mitsuba's curve files (`linearcurve`, `bsplinecurve`): one control point per line, four
//! numbers (x, y, z, radius), a blank line between curves. Every error names the file and
//! the line: a bad or missing number, a negative or non-finite radius, a curve with fewer
//! points than a segment needs, more points than glint can index.

use super::{read_file_bounded, MAX_MESH_FILE_BYTES};
use crate::geometry::{CurveBasis, MAX_CURVE_POINTS};
use std::path::Path;

/// The curves of a file, in its own space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurveFile {
    /// x, y, z, radius.
    pub points: Vec<[f32; 4]>,
    /// Curve `k` is `points[curve_starts[k]..curve_starts[k + 1]]`.
    pub curve_starts: Vec<u32>,
}

/// Longest line read (Mitsuba's limit too).
const MAX_LINE: usize = 1024;

fn err(path: &Path, line: usize, msg: impl std::fmt::Display) -> String {
    format!("{}:{}: {}", path.display(), line, msg)
}

pub fn read_curves(path: &Path, basis: CurveBasis) -> Result<CurveFile, String> {
    let data = read_file_bounded(path, MAX_MESH_FILE_BYTES)?;
    let text = std::str::from_utf8(&data).map_err(|_| format!("{}: not UTF-8 text", path.display()))?;
    parse_curves(path, text, basis)
}

/// Parses the text of a curve file (`path` names it in errors).
pub fn parse_curves(path: &Path, text: &str, basis: CurveBasis) -> Result<CurveFile, String> {
    let need = basis.degree() + 1;
    let mut out = CurveFile::default();
    // The line where the current curve began, while one is open.
    let mut open: Option<usize> = None;
    let close = |out: &mut CurveFile, open: &mut Option<usize>| -> Result<(), String> {
        if let Some(first_line) = open.take() {
            let start = *out.curve_starts.last().unwrap_or(&0) as usize;
            let n = out.points.len() - start;
            if n < need {
                return Err(err(
                    path,
                    first_line,
                    format!("a {} curve needs at least {need} control points, this one has {n}", basis.plugin()),
                ));
            }
            out.curve_starts.push(out.points.len() as u32);
        }
        Ok(())
    };
    out.curve_starts.push(0);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        if raw.len() > MAX_LINE {
            return Err(err(path, line, format!("line of {} characters (at most {MAX_LINE})", raw.len())));
        }
        let parts: Vec<&str> = raw.split_whitespace().collect();
        if parts.is_empty() {
            close(&mut out, &mut open)?;
            continue;
        }
        if parts.len() != 4 {
            return Err(err(
                path,
                line,
                format!("a control point is 4 numbers (x y z radius), this line has {}", parts.len()),
            ));
        }
        let mut p = [0.0f32; 4];
        for (k, s) in parts.iter().enumerate() {
            p[k] = s.parse::<f32>().map_err(|_| err(path, line, format!("'{s}' is not a number")))?;
            if !p[k].is_finite() {
                return Err(err(path, line, format!("'{s}' is not a finite number")));
            }
        }
        if p[3] < 0.0 {
            return Err(err(path, line, format!("radius {} is negative", p[3])));
        }
        if out.points.len() + 1 >= MAX_CURVE_POINTS {
            return Err(err(path, line, format!("more than {} control points", MAX_CURVE_POINTS - 1)));
        }
        open.get_or_insert(line);
        out.points.push(p);
    }
    close(&mut out, &mut open)?;
    if out.points.is_empty() {
        return Err(format!("{}: no control points", path.display()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, basis: CurveBasis) -> Result<CurveFile, String> {
        parse_curves(Path::new("hair.txt"), text, basis)
    }

    #[test]
    fn reads_mitsubas_example() {
        let f = parse(
            "-1.0 0.1 0.1 0.5\n 1.0 1.4 1.2 0.5\n\n-1.0 5.0 2.2 1\n-2.3 4.0 2.3 2\n 4.0 1.0 2.2 5\n 4.0 0.0 2.3 6\n",
            CurveBasis::Linear,
        )
        .unwrap();
        assert_eq!(f.curve_starts, vec![0, 2, 6]);
        assert_eq!(f.points[3], [-2.3, 4.0, 2.3, 2.0]);
        // Several blank lines (and trailing spaces, CRLF) separate curves just as one does.
        let f = parse("0 0 0 1\r\n1 0 0 1  \r\n\r\n\r\n0 1 0 1\n1 1 0 1", CurveBasis::Linear).unwrap();
        assert_eq!(f.curve_starts, vec![0, 2, 4]);
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            ("0 0 0 1\n1 0 0 -0.5\n", CurveBasis::Linear, "hair.txt:2: radius -0.5 is negative"),
            ("0 0 0 1\n1 0 0 NaN\n", CurveBasis::Linear, "hair.txt:2: 'NaN' is not a finite number"),
            ("0 0 0 1\n1 0 0\n", CurveBasis::Linear, "hair.txt:2: a control point is 4 numbers"),
            ("0 0 0 1\n1 0 0 x\n", CurveBasis::Linear, "hair.txt:2: 'x' is not a number"),
            ("0 0 0 1\n1 0 0 1\n\n0 0 0 1\n", CurveBasis::Linear, "hair.txt:4: a linearcurve curve needs at least 2"),
            ("0 0 0 1\n1 0 0 1\n2 0 0 1\n", CurveBasis::BSpline, "hair.txt:1: a bsplinecurve curve needs at least 4"),
            ("\n\n", CurveBasis::Linear, "hair.txt: no control points"),
        ];
        for (text, basis, want) in cases {
            let e = parse(text, basis).unwrap_err();
            assert!(e.starts_with(want), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
        let long = format!("0 0 0 {}\n", "1".repeat(2000));
        assert!(parse(&long, CurveBasis::Linear).unwrap_err().starts_with("hair.txt:1: line of"));
    }
}
