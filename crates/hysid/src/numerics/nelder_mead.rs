//! A small Nelder–Mead simplex minimiser for low-dimensional, possibly non-smooth criteria
//! (the equation-error profile over (α, d) is a fine staircase in d).
//!
//! Standard coefficients: reflection 1, expansion 2, contraction ½, shrink ½ (Nelder & Mead,
//! "A simplex method for function minimization", Computer Journal 7, 1965).

/// Minimises `f` from `x0` with initial steps `step` per coordinate, for at most `max_evals`
/// evaluations or until the simplex's spread of values falls below `ftol` (relative).
/// Returns the best point and its value.
pub fn nelder_mead(
    f: impl Fn(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    max_evals: usize,
    ftol: f64,
) -> (Vec<f64>, f64) {
    let n = x0.len();
    let mut simplex: Vec<Vec<f64>> = vec![x0.to_vec()];
    for i in 0..n {
        let mut v = x0.to_vec();
        v[i] += step[i];
        simplex.push(v);
    }
    let mut values: Vec<f64> = simplex.iter().map(|v| f(v)).collect();
    let mut evals = n + 1;
    while evals < max_evals {
        order(&mut simplex, &mut values);
        let (best, worst) = (values[0], values[n]);
        if (worst - best).abs() <= ftol * (best.abs() + f64::MIN_POSITIVE) {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|i| simplex[..n].iter().map(|v| v[i]).sum::<f64>() / n as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|i| centroid[i] + t * (simplex[n][i] - centroid[i]))
                .collect()
        };
        let reflected = along(-1.0);
        let fr = f(&reflected);
        evals += 1;
        if fr < values[0] {
            let expanded = along(-2.0);
            let fe = f(&expanded);
            evals += 1;
            (simplex[n], values[n]) = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < values[n - 1] {
            (simplex[n], values[n]) = (reflected, fr);
        } else {
            let contracted = if fr < values[n] {
                along(-0.5)
            } else {
                along(0.5)
            };
            let fc = f(&contracted);
            evals += 1;
            if fc < values[n].min(fr) {
                (simplex[n], values[n]) = (contracted, fc);
            } else {
                for k in 1..=n {
                    simplex[k] = (0..n)
                        .map(|i| simplex[0][i] + 0.5 * (simplex[k][i] - simplex[0][i]))
                        .collect();
                    values[k] = f(&simplex[k]);
                }
                evals += n;
            }
        }
    }
    order(&mut simplex, &mut values);
    (simplex.swap_remove(0), values[0])
}

/// Sorts the simplex by value, best first (non-finite values last).
fn order(simplex: &mut Vec<Vec<f64>>, values: &mut Vec<f64>) {
    let mut idx: Vec<usize> = (0..values.len()).collect();
    idx.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    *simplex = idx.iter().map(|&i| simplex[i].clone()).collect();
    *values = idx.iter().map(|&i| values[i]).collect();
}
