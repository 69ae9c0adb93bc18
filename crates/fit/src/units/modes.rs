//! The bottle's two modes (MODEL.md §13): which of a unit's components is f1's and which f2's.
//! A unit of eq. 1 has both; a real unit may ring one, and units may ring different ones. So the
//! components of every unit of a liquid are split in two groups by their log frequency
//! (two-means); the groups are two modes if their centres lie at least [`SEPARATE_MODES`] apart
//! and the groups are well apart for their spreads (Ashman's D = √2·|m1 − m2|/√(s1² + s2²) at
//! least [`MIN_ASHMAN_D`]: a spread of frequencies, such as gliding bubbles give, splits at any
//! place but has no gap), else every component rings the one mode there is, which is then f1
//! (and c = 1).

/// Two groups whose centres lie closer than this ratio of frequencies are one mode: the
/// spectrum's peaks are told apart at the same ratio.
pub const SEPARATE_MODES: f64 = super::super::spectrum::PEAK_SEPARATION;

/// The least Ashman's D of two modes: a uniform spread has 3.5, two peaks each narrower than a
/// tenth of their distance more than 14.
pub const MIN_ASHMAN_D: f64 = 4.0;

/// A mode is rung by at least this many components…
pub const MIN_MODE_COMPONENTS: usize = 3;
/// …and this share of them: a pitch one unit or two show (hum a fit took in, a splash) is no
/// mode of the bottle's, as a short mode is the bottle's only where units enough ring it.
pub const MIN_MODE_SHARE: f64 = 0.05;

/// How components are put in modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Modes {
    /// A unit's lower component is f1's, its higher f2's (eq. 1 as fitted, before the units of a
    /// liquid are seen together).
    ByOrder,
    /// Below this frequency f1's, above it f2's (Hz).
    Split(f64),
    /// One mode only: every component is f1's.
    One,
}

impl Modes {
    /// The modes before the units are seen together.
    pub fn by_order() -> Self {
        Modes::ByOrder
    }

    /// The modes of components at `frequencies` (Hz).
    pub fn of(frequencies: &[f64]) -> Self {
        let mut logs: Vec<f64> = frequencies
            .iter()
            .filter(|f| f.is_finite() && **f > 0.0)
            .map(|f| f.ln())
            .collect();
        if logs.len() < 2 {
            return Modes::One;
        }
        logs.sort_by(f64::total_cmp);
        let fewest = MIN_MODE_COMPONENTS.max((MIN_MODE_SHARE * logs.len() as f64).ceil() as usize);
        // A pitch fewer than `fewest` components ring (hum in two units' fits, a splash) is no
        // mode, and left in it would widen the group it joins until two modes no longer stand
        // apart (Ashman's D): a development draw's two hum components beside 27 units ringing
        // 322 and 825 Hz made one mode of them all.
        let logs = rung_by_enough(&logs, fewest);
        if logs.len() < 2 {
            return Modes::One;
        }
        // Two-means in one dimension: the best split of the sorted values, tried at every place.
        let total: f64 = logs.iter().sum();
        let total_squares: f64 = logs.iter().map(|x| x * x).sum();
        let (mut best, mut best_cost) = (None, f64::INFINITY);
        let (mut sum, mut squares) = (0.0, 0.0);
        for split in 1..logs.len() {
            sum += logs[split - 1];
            squares += logs[split - 1] * logs[split - 1];
            if split < fewest || logs.len() - split < fewest {
                continue;
            }
            let (n_low, n_high) = (split as f64, (logs.len() - split) as f64);
            let cost = (squares - sum * sum / n_low)
                + (total_squares - squares - (total - sum).powi(2) / n_high);
            if cost < best_cost {
                best_cost = cost;
                let (mean_low, mean_high) = (sum / n_low, (total - sum) / n_high);
                let variance_low = (squares / n_low - mean_low * mean_low).max(0.0);
                let variance_high =
                    ((total_squares - squares) / n_high - mean_high * mean_high).max(0.0);
                let ashman = std::f64::consts::SQRT_2 * (mean_high - mean_low)
                    / (variance_low + variance_high).sqrt().max(1e-12);
                best = Some((mean_low, mean_high, ashman));
            }
        }
        match best {
            Some((low, high, ashman))
                if high - low >= SEPARATE_MODES.ln() && ashman >= MIN_ASHMAN_D =>
            {
                Modes::Split((0.5 * (low + high)).exp())
            }
            _ => Modes::One,
        }
    }

    /// The mode (0: f1, 1: f2) of a component at `hz`, the `index`-th (by frequency) of a unit's
    /// `count`.
    pub fn mode_of(&self, hz: f64, index: usize, count: usize) -> usize {
        match *self {
            Modes::ByOrder => usize::from(count == 2 && index == 1),
            Modes::Split(boundary_hz) => usize::from(hz >= boundary_hz),
            Modes::One => 0,
        }
    }
}

/// The sorted log frequencies `logs` in runs of at least `fewest`, a run being values each less
/// than [`SEPARATE_MODES`]² above the one before: a cavity falling an octave over a few glugs (a
/// real bottle's 186, 144, 100 and 89 Hz), a bubble mode whose pitch varies by tens of per cent, or
/// a spread of frequencies is one run, kept whole; hum in two units' fits, well below the modes,
/// is a run of two, left out. (At [`SEPARATE_MODES`] itself that bottle's four f1 broke in two.)
fn rung_by_enough(logs: &[f64], fewest: usize) -> Vec<f64> {
    let apart = 2.0 * SEPARATE_MODES.ln();
    let mut kept = Vec::with_capacity(logs.len());
    let mut run_start = 0;
    for end in 1..=logs.len() {
        if end == logs.len() || logs[end] - logs[end - 1] >= apart {
            if end - run_start >= fewest {
                kept.extend_from_slice(&logs[run_start..end]);
            }
            run_start = end;
        }
    }
    kept
}

/// The units nearest in time on each side whose modes place a unit ringing one mode.
const NEIGHBOURS: usize = 2;

/// The split for a unit at `onset_s` that rings one mode, from the units nearest it in time that
/// ring both (`both`: their onsets (s) and f1, f2, in time order): halfway, in log frequency,
/// between their median f1 and f2. A falling cavity spreads f1 over an octave or more, so the
/// split of a liquid's frequencies taken together can put a full bottle's lone f1 above it; its
/// neighbours' modes place it where it rings. `None` where no unit rings both, or where its
/// neighbours' modes are not [`SEPARATE_MODES`] apart.
pub fn local_split(onset_s: f64, both: &[(f64, [f64; 2])]) -> Option<Modes> {
    let after = both.partition_point(|&(t, _)| t < onset_s);
    let near = &both[after.saturating_sub(NEIGHBOURS)..(after + NEIGHBOURS).min(both.len())];
    if near.is_empty() {
        return None;
    }
    let median_of = |k: usize| {
        let values: Vec<f64> = near.iter().map(|(_, hz)| hz[k]).collect();
        crate::stats::median(&values)
    };
    let (low, high) = (median_of(0), median_of(1));
    (high / low >= SEPARATE_MODES).then(|| Modes::Split((low * high).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_groups_apart_are_two_modes_and_one_group_is_one() {
        let two = Modes::of(&[80.0, 82.0, 300.0, 310.0, 79.0, 295.0]);
        let Modes::Split(boundary) = two else {
            panic!("{two:?}")
        };
        assert!((100.0..250.0).contains(&boundary), "{boundary}");
        assert_eq!(Modes::of(&[400.0, 420.0, 450.0, 380.0]), Modes::One);
        // Gliding bubbles: a spread from 300 to 1000 Hz without a gap.
        let spread: Vec<f64> = (0..40)
            .map(|i| 300.0 * (1000f64 / 300.0).powf(i as f64 / 39.0))
            .collect();
        assert_eq!(Modes::of(&spread), Modes::One);
        assert_eq!(two.mode_of(81.0, 0, 1), 0);
        assert_eq!(two.mode_of(305.0, 0, 1), 1);
        // One unit's hum beside twenty units' one mode is no mode of the bottle's.
        let mut hum = vec![515.0; 20];
        hum.push(52.0);
        assert_eq!(Modes::of(&hum), Modes::One);
        // Nor is a pitch in two units of a hundred.
        let mut splash = vec![515.0; 98];
        splash.extend([2000.0, 2010.0]);
        assert_eq!(Modes::of(&splash), Modes::One);
        // Three units of twenty ring a bright mode: two modes.
        let mut bright = vec![515.0; 20];
        bright.extend([1400.0, 1420.0, 1380.0]);
        assert!(matches!(Modes::of(&bright), Modes::Split(_)));
        // Two units' hum beside two modes that every unit rings leaves them two modes.
        let mut hummed: Vec<f64> = [322.0, 825.0].repeat(27);
        hummed.extend([49.0, 50.0]);
        let Modes::Split(boundary) = Modes::of(&hummed) else {
            panic!("hum made one mode of 322 and 825 Hz")
        };
        assert!((322.0..825.0).contains(&boundary), "{boundary}");
    }

    #[test]
    fn a_lone_mode_is_placed_by_its_neighbours_in_time() {
        // A cavity falling from 700 to 220 Hz beside a bubble at 1330 Hz: taken together, the
        // units' f1 put the split near 540 Hz, below a full bottle's lone f1 at 760 Hz.
        let both = [
            (0.2, [700.0, 1330.0]),
            (0.4, [690.0, 1328.0]),
            (3.0, [221.0, 1336.0]),
            (3.2, [220.0, 1331.0]),
            (3.4, [219.0, 1333.0]),
        ];
        let early = local_split(0.1, &both).expect("neighbours ring both modes");
        assert_eq!(early.mode_of(760.0, 0, 1), 0, "{early:?}");
        assert_eq!(early.mode_of(1300.0, 0, 1), 1, "{early:?}");
        // Late in the pour its neighbours are the late units.
        let late = local_split(3.3, &both).expect("neighbours ring both modes");
        assert_eq!(late.mode_of(230.0, 0, 1), 0, "{late:?}");
        assert_eq!(late.mode_of(900.0, 0, 1), 1, "{late:?}");
        // No unit rings both, or they ring one pitch: no split of their own.
        assert_eq!(local_split(0.5, &[]), None);
        assert_eq!(local_split(0.5, &[(1.0, [300.0, 330.0])]), None);
    }
}
