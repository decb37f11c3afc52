//! Rows (sample indices) as runs of consecutive indices, so that what is read on them is
//! read slice by slice, in loops the compiler vectorises, rather than index by index. A
//! refit's training rows are a few such runs (the recording's training part less its
//! flagged samples), and every run of the model gathers tens of thousands of them: index
//! by index that was a tenth of the work of `diagnose`.

use std::ops::Range;

/// `rows` as runs of consecutive indices, in their order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Spans {
    runs: Vec<Range<usize>>,
    count: usize,
}

impl Spans {
    /// The runs of `rows` (in any order: a run ends wherever the next row is not one more).
    pub fn of(rows: &[usize]) -> Self {
        let mut runs: Vec<Range<usize>> = Vec::new();
        for &i in rows {
            match runs.last_mut() {
                Some(r) if r.end == i && i != usize::MAX => r.end = i + 1,
                _ => runs.push(i..i.saturating_add(1)),
            }
        }
        Self { runs, count: rows.len() }
    }

    /// How many rows.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// `a` on the rows, in their order; `None` when a row is past its end.
    pub fn gather(&self, a: &[f64]) -> Option<Vec<f64>> {
        let mut out = Vec::with_capacity(self.count);
        for r in &self.runs {
            out.extend_from_slice(a.get(r.clone())?);
        }
        Some(out)
    }

    /// `f(a[i], b[i])` for each row `i`, in their order; `None` when a row is past the end
    /// of either.
    pub fn map2(&self, a: &[f64], b: &[f64], f: impl Fn(f64, f64) -> f64) -> Option<Vec<f64>> {
        let mut out = Vec::with_capacity(self.count);
        for r in &self.runs {
            let (a, b) = (a.get(r.clone())?, b.get(r.clone())?);
            out.extend(a.iter().zip(b).map(|(a, b)| f(*a, *b)));
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_read_what_the_rows_read_one_by_one() {
        let a: Vec<f64> = (0..40).map(|i| (i as f64 * 0.3).sin()).collect();
        let b: Vec<f64> = (0..35).map(|i| (i as f64 * 0.7).cos()).collect();
        let cases: Vec<Vec<usize>> = vec![
            vec![],
            vec![5],
            (0..30).collect(),
            (0..30).filter(|i| i % 7 != 3).collect(),
            vec![9, 3, 4, 5, 20, 19, 21, 22],
            vec![0, 0, 1],
        ];
        for rows in &cases {
            let s = Spans::of(rows);
            assert_eq!(s.len(), rows.len());
            let one_by_one: Option<Vec<f64>> = rows.iter().map(|&i| a.get(i).copied()).collect();
            assert_eq!(s.gather(&a), one_by_one, "{rows:?}");
            let diff: Option<Vec<f64>> = rows.iter().map(|&i| Some(a.get(i)? - b.get(i)?)).collect();
            assert_eq!(s.map2(&a, &b, |x, y| x - y), diff, "{rows:?}");
        }
        // A row past the end of either is no result.
        assert_eq!(Spans::of(&[3, 34, 35]).map2(&a, &b, |x, _| x), None);
        assert_eq!(Spans::of(&[39, 40]).gather(&a), None);
        assert_eq!(Spans::of(&[usize::MAX]).gather(&a), None);
        assert_eq!(Spans::of(&(0..3).collect::<Vec<_>>()).runs.len(), 1);
    }
}
