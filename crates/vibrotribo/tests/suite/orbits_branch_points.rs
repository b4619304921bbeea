//! Branch points against truth from outside the continuation: the paper's default chain is
//! symmetric under the mirror `x_i(t) ↦ −x_{N+1−i}(t + T/2)` (m₁ = m₃, equal springs,
//! dashpots and gaps; the base's `y(t + T/2) = −y(t)`), so its symmetric orbit can lose its
//! symmetry at a pitchfork. Every orbit is checked by direct simulation: the parent branch's
//! orbits are their own mirror images, the emerging branches' orbits are not, each returns to
//! its state after a period, its mirror image is an orbit too, and that mirror image is the
//! orbit of the other emerging branch. The pitchfork's own geometry is checked by shooting at
//! fixed Ω on both sides of the point.

use vibrotribo::orbits::{
    BifurcationKind, Branch, BranchEnd, BranchPoint, ContinuationOptions, ShootingOptions, continue_orbit,
    find_periodic_orbit, periodic_orbit_from_transient,
};
use vibrotribo::{ChainParams, ChainState, Frequency, SimOptions, Simulator};

/// The default case at Ω.
fn default_case(omega: f64) -> ChainParams {
    let mut p = ChainParams::default();
    p.excitation.frequency = Frequency::OmegaRatio(omega);
    p
}

/// Units of the state: positions in L = Σδ + A, velocities in L·ω.
fn scaled_distance(params: &ChainParams, a: &ChainState, b: &ChainState) -> f64 {
    let length = params.gaps.iter().sum::<f64>() + params.excitation.amplitude;
    let speed = length * params.omega();
    let dx = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (p - q).abs() / length);
    let dv = a
        .velocities
        .iter()
        .zip(&b.velocities)
        .map(|(p, q)| (p - q).abs() / speed);
    dx.chain(dv).fold(0.0, f64::max)
}

/// The state after `periods` excitation periods (a fraction allowed) from `s` at t = 0.
fn run(params: &ChainParams, s: &ChainState, periods: f64) -> ChainState {
    let mut sim = Simulator::new(params, s, SimOptions::default()).expect("a valid start");
    sim.run_until(periods * params.period(), &mut ())
        .expect("the orbit runs");
    sim.state()
}

/// The mirror image of the orbit through `s` at t = 0: `−x_{N+1−i}` of its state at T/2.
fn mirror(params: &ChainParams, s: &ChainState) -> ChainState {
    let h = run(params, s, 0.5);
    ChainState {
        positions: h.positions.iter().rev().map(|x| -x).collect(),
        velocities: h.velocities.iter().rev().map(|v| -v).collect(),
    }
}

/// How far the orbit through `p` is from its own mirror image (scaled).
fn asymmetry(p: &BranchPoint) -> f64 {
    let params = default_case(p.parameter);
    scaled_distance(&params, &mirror(&params, &p.state), &p.state)
}

/// The orbit through `s` at Ω is periodic with period 1: it returns to `s` to 1e-9 (scaled).
fn assert_returns(omega: f64, s: &ChainState, what: &str) {
    let params = default_case(omega);
    let d = scaled_distance(&params, &run(&params, s, 1.0), s);
    assert!(d < 1e-9, "{what} at Ω = {omega}: returns off by {d:e}");
}

fn continued() -> (Vec<Branch>, f64) {
    let start = periodic_orbit_from_transient(
        &default_case(0.7),
        &ChainState::at_rest(3),
        200,
        Some(1),
        &ShootingOptions::default(),
    )
    .expect("the default case's orbit at Ω = 0.7");
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", default_case, 0.7, 1.0, &start.state, 1, &options)
        .expect("the continuation runs");
    let bp = result.branches[0]
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::BranchPoint)
        .unwrap_or_else(|| panic!("no branch point: {:?}", result.branches[0].bifurcations));
    (result.branches.clone(), bp.parameter)
}

/// The default case's symmetric orbit loses its symmetry at a subcritical pitchfork at
/// Ω ≈ 0.80080 (just before its fold at 0.80085): both halves of the asymmetric branch are
/// followed, each is a branch of true asymmetric orbits, and the two are mirror images of
/// each other.
#[test]
fn the_default_cases_pitchfork_is_switched_at_and_both_halves_are_mirror_images() {
    let (branches, p_bp) = continued();
    let main = &branches[0];
    let (k, bp) = main
        .bifurcations
        .iter()
        .enumerate()
        .find(|(_, b)| b.kind == BifurcationKind::BranchPoint)
        .expect("a branch point");
    println!(
        "branch point at Ω = {p_bp:.10} (±{:.1e}); branches {:?}",
        bp.precision,
        branches
            .iter()
            .map(|b| (b.period, b.parent, b.points.len(), b.end.clone()))
            .collect::<Vec<_>>()
    );
    assert!((p_bp - 0.8008).abs() < 1e-3, "{p_bp}");
    assert!(bp.precision < 1e-7, "{}", bp.precision);
    let critical = bp
        .point
        .multipliers
        .iter()
        .map(|m| (m - 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    // The critical multiplier moves by ~1e3 per unit of Ω here (it is 1.067 at the fold
    // 5e-5 further on), so a location to 1e-8 leaves it within ~1e-5 of +1.
    assert!(critical < 1e-4, "no multiplier at +1: {:?}", bp.point.multipliers);
    // The parent branch is symmetric, up to its branch point too.
    for p in main.points.iter().step_by(20) {
        let a = asymmetry(p);
        assert!(
            a < 1e-9,
            "parent orbit at Ω = {} asymmetric by {a:e}",
            p.parameter
        );
    }
    assert!(asymmetry(&bp.point) < 1e-4, "{}", asymmetry(&bp.point));
    let (one, two) = (
        bp.child.expect("the first half followed"),
        bp.other_child.expect("the second half followed"),
    );
    assert_ne!(one, two);
    for c in [one, two] {
        let b = &branches[c];
        assert_eq!((b.period, b.parent), (1, Some((0, k))));
        assert!(b.points.len() > 20, "branch {c}: {} points", b.points.len());
        // Born at the branch point.
        let first = &b.points[0];
        assert!((first.parameter - p_bp).abs() < 1e-3, "{}", first.parameter);
        for p in b.points.iter().step_by(10) {
            assert_returns(p.parameter, &p.state, "emerging orbit");
            let params = default_case(p.parameter);
            assert_returns(p.parameter, &mirror(&params, &p.state), "its mirror image");
            if p_bp - p.parameter > 1e-3 {
                let a = asymmetry(p);
                assert!(a > 1e-3, "orbit at Ω = {} is symmetric ({a:e})", p.parameter);
            }
        }
    }
    // The two halves end at the range's end, where each is the other's mirror image.
    let (e1, e2) = (
        branches[one].points.last().unwrap(),
        branches[two].points.last().unwrap(),
    );
    assert_eq!(branches[one].end, BranchEnd::RangeEnd { parameter: 0.7 });
    assert_eq!(branches[two].end, BranchEnd::RangeEnd { parameter: 0.7 });
    let params = default_case(0.7);
    let d = scaled_distance(&params, &mirror(&params, &e1.state), &e2.state);
    let apart = scaled_distance(&params, &e1.state, &e2.state);
    println!("at Ω = 0.7 the halves are {apart:.3e} apart; one's mirror image is {d:.1e} from the other");
    assert!(apart > 1e-2, "the two halves coincide ({apart:e})");
    assert!(d < 1e-6, "the mirror image of one half is {d:e} from the other");
}

/// The pitchfork's geometry by shooting at fixed Ω, independent of the continuation: the
/// symmetric orbit's multiplier nearest +1 crosses it at the point, the asymmetric orbit
/// exists below it (where the branch emerges) with an asymmetry growing like the square root
/// of the distance, and shooting from it above the point finds only the symmetric orbit.
#[test]
fn the_pitchfork_is_where_the_symmetric_orbits_multiplier_crosses_one_and_asymmetry_grows_like_a_square_root()
{
    let (branches, p_bp) = continued();
    let bp = branches[0]
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::BranchPoint)
        .expect("a branch point");
    let options = ShootingOptions::default();
    // The guesses: the symmetric part of the located orbit (the mean of its state and its
    // mirror image's, which removes the critical antisymmetric direction), then the parent
    // branch's orbits nearest the point along it. Next to the pitchfork Newton's method may
    // land on an emerging asymmetric orbit; the first symmetric orbit found is the one.
    let params = default_case(p_bp);
    let image = mirror(&params, &bp.point.state);
    let mean = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| 0.5 * (a + b)).collect();
    let mut guesses = vec![ChainState {
        positions: mean(&bp.point.state.positions, &image.positions),
        velocities: mean(&bp.point.state.velocities, &image.velocities),
    }];
    let mut near: Vec<&BranchPoint> = branches[0].points.iter().collect();
    near.sort_by(|a, b| {
        let d = |p: &BranchPoint| (p.arclength - bp.point.arclength).abs();
        d(a).total_cmp(&d(b))
    });
    guesses.extend(near.iter().take(6).map(|p| p.state.clone()));
    let leading = |omega: f64| {
        let params = default_case(omega);
        let o = guesses
            .iter()
            .filter_map(|g| find_periodic_orbit(&params, g, 1, &options).ok())
            .find(|o| scaled_distance(&params, &mirror(&params, &o.state), &o.state) < 1e-8)
            .unwrap_or_else(|| panic!("no symmetric orbit found by shooting at Ω = {omega}"));
        o.multipliers
            .iter()
            .filter(|m| m.im.abs() < 1e-12)
            .map(|m| m.re - 1.0)
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .expect("a real multiplier")
    };
    let (below, above) = (leading(p_bp - 1e-5), leading(p_bp + 1e-5));
    println!("symmetric orbit: λ − 1 = {below:e} below, {above:e} above");
    assert!(below < 0.0 && above > 0.0);
    // Where the shot multiplier crosses +1, by linear interpolation over the ±1e-5 bracket,
    // against the continuation's branch point.
    let crossing = p_bp - 1e-5 + 2e-5 * below / (below - above);
    println!("shot crossing at Ω = {crossing:.10}, continuation's branch point {p_bp:.10}");
    assert!((crossing - p_bp).abs() < 1e-6, "{crossing} vs {p_bp}");
    // Asymmetry along the emerging branch against the distance below the point.
    let half = &branches[bp.child.expect("followed")];
    let near: Vec<(f64, f64)> = half
        .points
        .iter()
        .filter(|p| (2e-6..2e-4).contains(&(p_bp - p.parameter)))
        .map(|p| ((p_bp - p.parameter).ln(), asymmetry(p).ln()))
        .collect();
    assert!(near.len() >= 3, "{} points near the branch point", near.len());
    let n = near.len() as f64;
    let (mx, my) = near
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let slope = near.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / near.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("asymmetry ∝ (Ω_bp − Ω)^{slope:.3} over {} points", near.len());
    assert!((slope - 0.5).abs() < 0.05, "exponent {slope}");
    // Above the point shooting from an asymmetric orbit finds the symmetric one.
    let guess = near_point(half, p_bp - 1e-4);
    let o = find_periodic_orbit(&default_case(p_bp + 2e-5), &guess.state, 1, &options);
    if let Ok(o) = o {
        let params = default_case(p_bp + 2e-5);
        let a = scaled_distance(&params, &mirror(&params, &o.state), &o.state);
        assert!(a < 1e-8, "an asymmetric orbit above the branch point ({a:e})");
    }
}

/// The point of `b` nearest the parameter `p`.
fn near_point(b: &Branch, p: f64) -> &BranchPoint {
    b.points
        .iter()
        .min_by(|x, y| (x.parameter - p).abs().total_cmp(&(y.parameter - p).abs()))
        .expect("points")
}
