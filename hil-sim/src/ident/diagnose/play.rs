//! The play operator (backlash), the loop of the play host's terms ([`super::contenders::plays`]).

/// A play operator (backlash) of radius `r`: its output follows `x` within `±r`, starting
/// at `x[0]`.
pub fn play(x: &[f64], r: f64) -> Vec<f64> {
    let mut s = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            s = s.max(v - r).min(v + r);
            s
        })
        .collect()
}

/// [`play`] of `x` for each radius of `radii`, the same values to the bit, the operators
/// run side by side in one pass over `x` (each is a chain of a max and a min per sample,
/// which one operator alone leaves the processor waiting on).
pub fn plays(x: &[f64], radii: &[f64]) -> Vec<Vec<f64>> {
    const SIDE: usize = 4;
    let mut out: Vec<Vec<f64>> = radii.iter().map(|_| Vec::with_capacity(x.len())).collect();
    let first = x.first().copied().unwrap_or(0.0);
    for (rs, outs) in radii.chunks(SIDE).zip(out.chunks_mut(SIDE)) {
        // A group short of SIDE repeats its last radius, whose copies are not kept.
        let r: [f64; SIDE] = std::array::from_fn(|k| rs.get(k).or(rs.last()).copied().unwrap_or(0.0));
        let mut s = [first; SIDE];
        for v in x {
            for k in 0..SIDE {
                s[k] = s[k].max(v - r[k]).min(v + r[k]);
            }
            for (o, s) in outs.iter_mut().zip(s) {
                o.push(s);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plays_side_by_side_are_each_play_to_the_bit() {
        let x: Vec<f64> = (0..500).map(|i| (i as f64 * 0.05).sin() + 0.3 * (i as f64 * 0.31).cos()).collect();
        for n in 0..10 {
            let radii: Vec<f64> = (0..n).map(|k| 0.01 + 0.07 * k as f64).collect();
            let got = plays(&x, &radii);
            assert_eq!(got.len(), n);
            for (g, r) in got.iter().zip(&radii) {
                let want = play(&x, *r);
                assert!(g.len() == want.len() && g.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
        assert_eq!(plays(&[], &[0.1, 0.2]), vec![Vec::<f64>::new(), Vec::new()]);
    }
}
