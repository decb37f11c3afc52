//! Where each sample of a recording is in its file, for messages: the file line of a CSV data
//! row (the header is line 1), or the sample number of a MAT-file. Rows follow one another on
//! consecutive lines except after a blank line or a quoted field that spans lines, so the map
//! stores the first row's line and only the rows where that run of consecutive lines breaks:
//! a few words for a file of millions of rows, where a line per row would cost 8 bytes each.

/// The file line (or sample number) of every sample, 1-based.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LineMap {
    rows: usize,
    /// `(row, line)`: from `row` on, row `r` is on line `line + (r − row)`; sorted by row,
    /// the first entry for row 0.
    breaks: Vec<(usize, u64)>,
}

impl LineMap {
    /// Samples numbered 1..=rows (a MAT-file, or a recording made in memory).
    pub fn numbered(rows: usize) -> Self {
        Self { rows, breaks: if rows > 0 { vec![(0, 1)] } else { Vec::new() } }
    }

    /// The next row is on file line `line`.
    pub fn push(&mut self, line: u64) {
        let expected = self.breaks.last().map(|&(row, at)| at + (self.rows - row) as u64);
        if expected != Some(line) {
            self.breaks.push((self.rows, line));
        }
        self.rows += 1;
    }

    /// The line of row `i` (0-based), if there is such a row.
    pub fn get(&self, i: usize) -> Option<u64> {
        if i >= self.rows {
            return None;
        }
        let k = self.breaks.partition_point(|&(row, _)| row <= i);
        let &(row, line) = self.breaks.get(k.checked_sub(1)?)?;
        Some(line + (i - row) as u64)
    }

    /// Keep the first `rows` rows.
    pub fn truncate(&mut self, rows: usize) {
        self.rows = self.rows.min(rows);
        let k = self.breaks.partition_point(|&(row, _)| row < self.rows);
        self.breaks.truncate(k);
    }

    pub fn len(&self) -> usize {
        self.rows
    }

    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }
}

#[cfg(test)]
mod tests {
    use super::LineMap;

    #[test]
    fn keeps_every_rows_line_with_a_word_per_break() {
        let lines = [2u64, 3, 4, 6, 7, 10, 11, 12];
        let mut m = LineMap::default();
        for l in lines {
            m.push(l);
        }
        assert_eq!(m.len(), lines.len());
        assert_eq!((0..lines.len()).map(|i| m.get(i).unwrap()).collect::<Vec<_>>(), lines);
        assert_eq!(m.get(lines.len()), None);
        assert_eq!(m.breaks.len(), 3, "breaks at rows 0, 3 and 5 only");
        m.truncate(5);
        assert_eq!((m.len(), m.get(4), m.get(5), m.breaks.len()), (5, Some(7), None, 2));
        let n = LineMap::numbered(4);
        assert_eq!((0..4).map(|i| n.get(i).unwrap()).collect::<Vec<_>>(), [1, 2, 3, 4]);
    }
}
