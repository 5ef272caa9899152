//! Paper 003's LDR compositing (Section 7.1): intensity transfers S_ij, the codes each source
//! takes from a vertex when the sources are assumed occluded in two sets (Figure 4), and the
//! error of that assumption when P random sources are occluded instead (Figure 3).

use glam::Vec3;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use real_scene::CameraResponse;

/// T of a radiance in (unrounded) 8-bit codes.
#[must_use]
pub fn codes(response: &CameraResponse, l: Vec3) -> Vec3 {
    Vec3::from_array(l.to_array().map(|c| 255.0 * response.curve(c)))
}

/// Figure 4 for one vertex of radiance `radiance`: its sources' radiance transfers in the order
/// given (decreasing transfer) and each one's set (0 or 1); returns S per source. Each set
/// starts from the whole radiance and loses its sources' transfers in turn; a source's S is the
/// codes its set lost with it.
#[must_use]
pub fn intensity_transfers(response: &CameraResponse, radiance: Vec3, transfers: &[Vec3], sets: &[u8]) -> Vec<Vec3> {
    let start = codes(response, radiance);
    let (mut v, mut c) = ([radiance; 2], [start; 2]);
    transfers
        .iter()
        .zip(sets)
        .map(|(l, &set)| {
            let k = usize::from(set.min(1));
            v[k] -= *l;
            let next = codes(response, v[k]);
            let s = c[k] - next;
            c[k] = next;
            s
        })
        .collect()
}

/// One vertex for Figure 3's trials: its radiance and its sources' transfers, largest first.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// L_i.
    pub radiance: Vec3,
    /// L_ij, in decreasing order.
    pub transfers: Vec<Vec3>,
}

/// Figure 3: for P = 0..=N occluded sources, the RMS error in codes (over channels, trials and
/// datasets) of I - sum S_ij M_ij against T(L - sum L_ij M_ij), with the intensity transfers
/// computed assuming a share `first_share` of the sources (chosen at random, fixed per dataset)
/// form the first set, and P sources picked at random per trial.
#[must_use]
pub fn figure3(
    datasets: &[Dataset],
    response: &CameraResponse,
    first_share: f64,
    trials: usize,
    seed: u64,
) -> Vec<(usize, f64)> {
    let n = datasets.iter().map(|d| d.transfers.len()).min().unwrap_or(0);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let prepared: Vec<(Vec3, Vec<Vec3>, Vec<Vec3>)> = datasets
        .iter()
        .map(|d| {
            let transfers = d.transfers[..n].to_vec();
            let mut ids: Vec<usize> = (0..n).collect();
            ids.shuffle(&mut rng);
            let first = (first_share.clamp(0.0, 1.0) * n as f64).round() as usize;
            let mut sets = vec![1u8; n];
            for &j in &ids[..first] {
                sets[j] = 0;
            }
            let s = intensity_transfers(response, d.radiance, &transfers, &sets);
            (d.radiance, transfers, s)
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    (0..=n)
        .map(|p| {
            let (mut sq, mut count) = (0.0f64, 0usize);
            for (radiance, transfers, s) in &prepared {
                let start = codes(response, *radiance);
                for _ in 0..trials {
                    order.shuffle(&mut rng);
                    let occluded = &order[..p];
                    let exact = codes(response, *radiance - occluded.iter().map(|&j| transfers[j]).sum::<Vec3>());
                    let approx = start - occluded.iter().map(|&j| s[j]).sum::<Vec3>();
                    let e = approx - exact;
                    sq += f64::from(e.dot(e));
                    count += 3;
                }
            }
            (p, (sq / count.max(1) as f64).sqrt())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn response() -> CameraResponse {
        CameraResponse { exposure: 1.0, gamma: 2.2, white: 1.0 }
    }

    fn dataset(n: usize) -> Dataset {
        // sources sending 40 % of the vertex's radiance, geometrically decreasing
        let raw: Vec<f32> = (0..n).map(|j| 0.93f32.powi(j as i32)).collect();
        let total: f32 = raw.iter().sum();
        Dataset {
            radiance: Vec3::new(0.6, 0.5, 0.4),
            transfers: raw.iter().map(|r| Vec3::new(0.24, 0.2, 0.16) * (r / total)).collect(),
        }
    }

    #[test]
    fn intensity_transfers_are_exact_when_a_set_is_occluded_as_assumed() {
        let (t, d) = (response(), dataset(12));
        let sets: Vec<u8> = (0..12).map(|j| (j % 2) as u8).collect();
        let s = intensity_transfers(&t, d.radiance, &d.transfers, &sets);
        for set in [0u8, 1] {
            let occluded: Vec<usize> = (0..12).filter(|&j| sets[j] == set).collect();
            let exact = codes(&t, d.radiance - occluded.iter().map(|&j| d.transfers[j]).sum::<Vec3>());
            let approx = codes(&t, d.radiance) - occluded.iter().map(|&j| s[j]).sum::<Vec3>();
            assert!((exact - approx).abs().max_element() < 1e-3, "set {set}: {approx} vs {exact}");
        }
        // each S is positive and a set's S sum to the codes the whole set takes
        assert!(s.iter().all(|v| v.min_element() > 0.0));
    }

    #[test]
    fn the_responses_toe_and_shoulder_give_finite_non_negative_transfers() {
        let t = response();
        let sets: Vec<u8> = (0..12).map(|j| (j % 2) as u8).collect();
        for scale in [1e-4f32, 1.0, 3.0, 50.0] {
            let d = dataset(12);
            let radiance = d.radiance * scale;
            let transfers: Vec<Vec3> = d.transfers.iter().map(|l| *l * scale).collect();
            let s = intensity_transfers(&t, radiance, &transfers, &sets);
            assert!(s.iter().all(|v| v.is_finite() && v.min_element() >= 0.0), "x{scale}: {s:?}");
            // each set's transfers add up to the codes the set takes away, clipped or not
            for set in [0u8, 1] {
                let lost: Vec3 = (0..12).filter(|&j| sets[j] == set).map(|j| s[j]).sum();
                let rest = radiance - (0..12).filter(|&j| sets[j] == set).map(|j| transfers[j]).sum::<Vec3>();
                let want = codes(&t, radiance) - codes(&t, rest);
                assert!((lost - want).abs().max_element() < 1e-3, "x{scale} set {set}: {lost} vs {want}");
            }
        }
        // a saturated vertex: its first transfers take nothing until the set drops below white
        let d = dataset(12);
        let s = intensity_transfers(
            &t,
            d.radiance * 50.0,
            &d.transfers.iter().map(|l| *l * 50.0).collect::<Vec<_>>(),
            &sets,
        );
        assert_eq!(s[0], Vec3::ZERO);
    }

    #[test]
    fn the_split_errs_least_at_its_own_share_and_at_no_occlusion() {
        let (t, data) = (response(), vec![dataset(50), dataset(50)]);
        let half = figure3(&data, &t, 0.5, 400, 1);
        assert_eq!(half.len(), 51);
        assert!(half[0].1 < 1e-4, "nothing occluded, nothing wrong: {}", half[0].1);
        // The error grows from P = 0, dips again where P matches the assumed split (the sets'
        // chains end where the occluded sources do), and grows past it; a split with a larger
        // second set dips later (Figure 3's panels).
        let trough = |c: &[(usize, f64)]| c[10..=45].iter().min_by(|a, b| a.1.total_cmp(&b.1)).map_or(0, |x| x.0);
        let quarter = figure3(&data, &t, 0.25, 400, 1);
        let tenth = figure3(&data, &t, 0.1, 400, 1);
        let (h, q, e) = (trough(&half), trough(&quarter), trough(&tenth));
        assert!((18..=30).contains(&h), "50/50 dips at P = {h}: {half:?}");
        assert!(half[h].1 < half[12].1 && half[h].1 < half[40].1, "{half:?}");
        assert!(q > h && e > q, "dips at {h}, {q}, {e}");
    }
}
