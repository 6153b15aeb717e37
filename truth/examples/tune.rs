//! Nelder–Mead over the Shredder law's main parameters against Table 1.
use trackbelt_truth::drop::{Contact, DropConfig};
use trackbelt_truth::law::*;

const TARGET: [f64; 6] = [324.0, 1062.0, 225.0, 1082.0, 0.74, 0.73];
const TOL: [f64; 6] = [0.03, 0.015, 0.04, 0.015, 0.05, 0.1];

fn figures(p: &[f64], n: usize) -> Option<[f64; 6]> {
    let mut law = BendingLaw::shredder();
    law.ei_soft *= p[0].exp();
    law.ei_zero *= p[1].exp();
    law.ei_back *= p[2].exp();
    law.ei_hard *= p[3].exp();
    law.kappa_h *= p[5].exp();
    let c = 0.023 * p[4].exp();
    let mat = Material {
        elastic: law,
        damping: DampingLaw::Linear { c },
        friction: FrictionLaw::None,
        payne: None,
        thermal: None,
    };
    let cfg = DropConfig {
        length_m: 2.45,
        thickness_m: 0.008,
        mass_kg: 6.4,
        nodes: n,
        ea_n: 5e4,
        material: mat,
        ei_scale: vec![1.0; n],
        floor: Contact::floor(),
    };
    let s = cfg.settle(0).ok()?;
    let run = cfg.drop(&s, 1.3, 0.05, 4.0, 0.001).ok()?;
    let (t, l) = run.period_and_decrement()?;
    Some([
        s.hs_m * 1e3,
        s.ws_m * 1e3,
        run.hd_m * 1e3,
        run.wd_m * 1e3,
        t,
        l,
    ])
}

fn cost(p: &[f64], n: usize) -> f64 {
    match figures(p, n) {
        None => 1e9,
        Some(f) => f
            .iter()
            .zip(TARGET)
            .zip(TOL)
            .map(|((a, b), t)| ((a / b - 1.0) / t).powi(2))
            .sum(),
    }
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().unwrap())
        .unwrap_or(36);
    let d = 6;
    let mut simplex: Vec<Vec<f64>> = vec![vec![0.0; d]];
    for i in 0..d {
        let mut p = vec![0.0; d];
        p[i] = 0.2;
        simplex.push(p);
    }
    let mut f: Vec<f64> = simplex.iter().map(|p| cost(p, n)).collect();
    for it in 0..120 {
        let mut idx: Vec<usize> = (0..=d).collect();
        idx.sort_by(|&a, &b| f[a].partial_cmp(&f[b]).unwrap());
        simplex = idx.iter().map(|&i| simplex[i].clone()).collect();
        f = idx.iter().map(|&i| f[i]).collect();
        if it % 10 == 0 {
            eprintln!(
                "it {it} best {:.3} p {:?} fig {:?}",
                f[0],
                simplex[0]
                    .iter()
                    .map(|x| (x.exp() * 1000.0).round() / 1000.0)
                    .collect::<Vec<_>>(),
                figures(&simplex[0], n)
            );
        }
        let c: Vec<f64> = (0..d)
            .map(|j| simplex[..d].iter().map(|p| p[j]).sum::<f64>() / d as f64)
            .collect();
        let pt =
            |t: f64| -> Vec<f64> { (0..d).map(|j| c[j] + t * (simplex[d][j] - c[j])).collect() };
        let r = pt(-1.0);
        let fr = cost(&r, n);
        if fr < f[0] {
            let e = pt(-2.0);
            let fe = cost(&e, n);
            if fe < fr {
                simplex[d] = e;
                f[d] = fe;
            } else {
                simplex[d] = r;
                f[d] = fr;
            }
        } else if fr < f[d - 1] {
            simplex[d] = r;
            f[d] = fr;
        } else {
            let k = pt(0.5);
            let fk = cost(&k, n);
            if fk < f[d] {
                simplex[d] = k;
                f[d] = fk;
            } else {
                for i in 1..=d {
                    simplex[i] = (0..d)
                        .map(|j| simplex[0][j] + 0.5 * (simplex[i][j] - simplex[0][j]))
                        .collect();
                    f[i] = cost(&simplex[i], n);
                }
            }
        }
    }
    let mut best = 0;
    for i in 0..=d {
        if f[i] < f[best] {
            best = i;
        }
    }
    println!(
        "best {:.3} factors {:?} fig {:?}",
        f[best],
        simplex[best].iter().map(|x| x.exp()).collect::<Vec<_>>(),
        figures(&simplex[best], n)
    );
}
