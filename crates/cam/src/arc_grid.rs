//! Parameter lines at equal steps of arc length: a surface whose parametric speed varies
//! (STEP fits often run 5:1) sampled at the largest speed everywhere would be that much denser
//! than needed where it is slow. The verifying simulation's dexel grid and the gouge index's
//! surface samples both stand on these lines.

/// Values of the other parameter at which the speed is taken (its largest counts).
const SPEED_SAMPLES: usize = 33;

/// Samples along a parameter for [`arc_nodes`].
const ARC_SAMPLES: usize = 256;

/// The cumulative arc length along one parameter over `range` (at [`ARC_SAMPLES`] + 1 equally
/// spaced values), the speed at each value being the largest `speed(t, s)` over
/// [`SPEED_SAMPLES`] values of the other parameter `s` in `across`, with a 5 % margin for what
/// falls between samples, and each interval taken at the larger of its ends' speeds. Returns
/// the (parameter, length) samples and the total length.
pub fn arc_nodes(
    speed: impl Fn(f64, f64) -> f64,
    range: (f64, f64),
    across: (f64, f64),
) -> (Vec<(f64, f64)>, f64) {
    let at = |k: usize, n: usize, r: (f64, f64)| r.0 + (r.1 - r.0) * k as f64 / n as f64;
    let fastest: Vec<f64> = (0..=ARC_SAMPLES)
        .map(|k| {
            let t = at(k, ARC_SAMPLES, range);
            (0..SPEED_SAMPLES)
                .map(|j| speed(t, at(j, SPEED_SAMPLES - 1, across)))
                .filter(|x| x.is_finite())
                .fold(0.0_f64, f64::max)
                * 1.05
        })
        .collect();
    let mut out = Vec::with_capacity(ARC_SAMPLES + 1);
    let mut length = 0.0;
    out.push((range.0, 0.0));
    for k in 1..=ARC_SAMPLES {
        let dt = (range.1 - range.0) / ARC_SAMPLES as f64;
        length += fastest[k - 1].max(fastest[k]) * dt;
        out.push((at(k, ARC_SAMPLES, range), length));
    }
    (out, length)
}

/// `n` parameter values (n ≥ 2) at equal steps of the length in `samples` (from
/// [`arc_nodes`]), the first and last at the range's ends; n = 1 gives the start.
pub fn spread(samples: &[(f64, f64)], n: usize) -> Vec<f64> {
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return Vec::new();
    };
    if n < 2 || last.1 <= 0.0 {
        return (0..n.max(1))
            .map(|k| first.0 + (last.0 - first.0) * k as f64 / (n.max(2) - 1) as f64)
            .collect();
    }
    let mut out = Vec::with_capacity(n);
    let mut seg = 0;
    for k in 0..n {
        let target = last.1 * k as f64 / (n - 1) as f64;
        while seg + 2 < samples.len() && samples[seg + 1].1 < target {
            seg += 1;
        }
        let (a, b) = (samples[seg], samples[seg + 1]);
        let t = if b.1 > a.1 {
            ((target - a.1) / (b.1 - a.1)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(a.0 + (b.0 - a.0) * t);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lines_at_equal_arc_length_keep_every_cell_within_the_spacing() {
        // Speed 1 + 3t on [0, 1] (length 2.5), the same across: the nodes bunch where it is
        // fast, and no step's true length ∫(1 + 3t) dt exceeds the cell.
        let (samples, length) = arc_nodes(|t, _| 1.0 + 3.0 * t, (0.0, 1.0), (0.0, 1.0));
        assert!(
            (2.5 * 1.05..2.5 * 1.05 * 1.01).contains(&length),
            "{length}"
        );
        let cell = 0.05;
        let n = (length / cell).ceil() as usize + 1;
        let nodes = spread(&samples, n);
        assert_eq!(nodes.len(), n);
        assert_eq!((nodes[0], nodes[n - 1]), (0.0, 1.0));
        let true_length = |a: f64, b: f64| (b - a) + 1.5 * (b * b - a * a);
        let steps: Vec<f64> = nodes.windows(2).map(|w| true_length(w[0], w[1])).collect();
        assert!(steps.iter().all(|&d| d > 0.0 && d <= cell), "{steps:?}");
        // Nearly equal: a uniform grid would need the fast end's spacing everywhere (4 × 1.05
        // / 0.05 = 84 steps instead of 53).
        let (lo, hi) = steps
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), &d| (a.min(d), b.max(d)));
        assert!(lo > 0.9 * hi, "{lo} {hi}");
        assert!(n - 1 < 60, "{n}");
    }
}
