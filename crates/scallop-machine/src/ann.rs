//! Learned inverse kinematics of the MX330, as a **baseline only** (kinematics.md 6,
//! feature `ann-baseline`, off by default): the thesis's multilayer perceptrons (Table V.3
//! sizes, logistic units with a bias input, online back-propagation with momentum,
//! `w(t+1) = w(t) + mu e x + m (w(t) - w(t-1))`), trained on a 5^5 full factorial of the
//! joints pushed through the exact forward kinematics. Never on the production path: the
//! closed form is exact to ~1e-13 mm for a few dozen flops; this module exists to measure
//! how far the thesis's approach is from it.
//!
//! [DECISION]s the thesis leaves open: inputs and targets are min-max scaled to [0, 1]
//! over the data set; the 3125 samples are shuffled with a fixed seed and split in three
//! equal thirds (train / test / validation; the thesis's split is inconsistent, E22);
//! weights start uniform in +-0.5 (seeded); training runs a fixed number of epochs and
//! keeps the weights of the epoch with the lowest validation error.

use scallop_geom::rng::SplitMix64;

use crate::chain::{Joints, Kinematics};

/// One network of Table V.3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetSpec {
    /// Joint predicted (`X`, `Y`, `Z`, `A`, `C`).
    pub joint: &'static str,
    /// Hidden layer sizes.
    pub hidden: [usize; 2],
    /// Learning rate mu.
    pub learning_rate: f64,
    /// Momentum m.
    pub momentum: f64,
    /// The thesis's validation MSE (normalised targets).
    pub thesis_validation_mse: f64,
}

/// Table V.3 of the thesis.
pub const TABLE_V3: [NetSpec; 5] = [
    NetSpec { joint: "X", hidden: [25, 11], learning_rate: 0.11, momentum: 0.3, thesis_validation_mse: 0.0052 },
    NetSpec { joint: "Y", hidden: [22, 11], learning_rate: 0.71, momentum: 0.8, thesis_validation_mse: 0.0057 },
    NetSpec { joint: "Z", hidden: [18, 16], learning_rate: 0.71, momentum: 0.1, thesis_validation_mse: 0.0052 },
    NetSpec { joint: "A", hidden: [10, 14], learning_rate: 0.61, momentum: 0.7, thesis_validation_mse: 1.967e-4 },
    NetSpec { joint: "C", hidden: [6, 12], learning_rate: 0.41, momentum: 0.9, thesis_validation_mse: 1.943e-4 },
];

/// A fully connected logistic network with one bias input per layer.
#[derive(Debug, Clone, PartialEq)]
pub struct Mlp {
    sizes: Vec<usize>,
    /// Per layer: `out x (in + 1)` weights, the last column the bias.
    weights: Vec<Vec<f64>>,
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

impl Mlp {
    /// A network with layer sizes `sizes` (inputs first), weights uniform in +-0.5.
    #[must_use]
    pub fn new(sizes: &[usize], rng: &mut SplitMix64) -> Mlp {
        let weights = sizes.windows(2).map(|w| (0..w[1] * (w[0] + 1)).map(|_| rng.unit() - 0.5).collect()).collect();
        Mlp { sizes: sizes.to_vec(), weights }
    }

    /// Activations of every layer for `input` (inputs first).
    fn forward(&self, input: &[f64]) -> Vec<Vec<f64>> {
        let mut acts = vec![input.to_vec()];
        for (l, w) in self.weights.iter().enumerate() {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let x = &acts[l];
            let out: Vec<f64> = (0..n_out)
                .map(|o| {
                    let row = &w[o * (n_in + 1)..(o + 1) * (n_in + 1)];
                    sigmoid(row[..n_in].iter().zip(x).map(|(a, b)| a * b).sum::<f64>() + row[n_in])
                })
                .collect();
            acts.push(out);
        }
        acts
    }

    /// The network's output (its single output unit) for `input`.
    #[must_use]
    pub fn predict(&self, input: &[f64]) -> f64 {
        self.forward(input).last().map_or(0.0, |o| o[0])
    }

    /// One online back-propagation step with momentum on `(input, target)`; `velocity`
    /// holds the previous weight change of every weight (same shape as the weights).
    fn train_one(&mut self, input: &[f64], target: f64, rate: f64, momentum: f64, velocity: &mut [Vec<f64>]) {
        let acts = self.forward(input);
        let layers = self.weights.len();
        // Error signals, output layer first: delta = (target - y) y (1 - y).
        let mut delta: Vec<f64> = acts[layers].iter().map(|y| (target - y) * y * (1.0 - y)).collect();
        for l in (0..layers).rev() {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let x = &acts[l];
            let previous: Vec<f64> = (0..n_in)
                .map(|i| {
                    let back: f64 = (0..n_out).map(|o| self.weights[l][o * (n_in + 1) + i] * delta[o]).sum();
                    x[i] * (1.0 - x[i]) * back
                })
                .collect();
            for (o, d) in delta.iter().enumerate() {
                for (i, xi) in x.iter().copied().chain(std::iter::once(1.0)).enumerate() {
                    let k = o * (n_in + 1) + i;
                    let change = rate * d * xi + momentum * velocity[l][k];
                    self.weights[l][k] += change;
                    velocity[l][k] = change;
                }
            }
            delta = previous;
        }
    }
}

/// The data set: inputs and targets per sample, already scaled to [0, 1].
#[derive(Debug, Clone)]
pub struct DataSet {
    /// Raw joints (X, Y, Z in mm, A, C in rad) of every sample.
    pub joints: Vec<Joints>,
    /// Raw network inputs per joint net: (Px, Py, Pz, A, C) for X/Y/Z, (Ok, rho) for A,
    /// (Oi, Oj) for C.
    pub inputs: [Vec<Vec<f64>>; 5],
    /// Min and max of each raw input column, per net.
    pub input_range: [Vec<(f64, f64)>; 5],
    /// Min and max of each joint (the target scaling).
    pub target_range: [(f64, f64); 5],
}

fn level(lo: f64, hi: f64, k: usize) -> f64 {
    lo + (hi - lo) * k as f64 / 4.0
}

/// The 5^5 full factorial over the MX330's joints (kinematics.md 6): C in {-144, -72, 0,
/// 72, 144} deg, A in 5 levels on [-125, 10] deg, X, Y, Z in 5 levels on their strokes,
/// pushed through `kin`'s forward kinematics.
#[must_use]
pub fn factorial_data(kin: &Kinematics) -> DataSet {
    let m = kin.machine();
    let stroke = |i: usize| m.axes()[i].joint_limits().unwrap_or((0.0, 0.0));
    let (x, y, z) = (stroke(0), stroke(1), stroke(2));
    let mut joints = Vec::with_capacity(3125);
    for ix in 0..5 {
        for iy in 0..5 {
            for iz in 0..5 {
                for ia in 0..5 {
                    for ic in 0..5 {
                        joints.push(Joints::new(
                            level(x.0, x.1, ix),
                            level(y.0, y.1, iy),
                            level(z.0, z.1, iz),
                            level(-125f64.to_radians(), 10f64.to_radians(), ia),
                            level(-144f64.to_radians(), 144f64.to_radians(), ic),
                        ));
                    }
                }
            }
        }
    }
    let mut raw: [Vec<Vec<f64>>; 5] = Default::default();
    for q in &joints {
        let pose = kin.fk(q);
        let (p, o) = (pose.tip, pose.axis);
        let position = vec![p.x, p.y, p.z, q[3], q[4]];
        raw[0].push(position.clone());
        raw[1].push(position.clone());
        raw[2].push(position);
        raw[3].push(vec![o.z, o.x.hypot(o.y)]);
        raw[4].push(vec![o.x, o.y]);
    }
    let mut input_range: [Vec<(f64, f64)>; 5] = Default::default();
    for (net, rows) in raw.iter_mut().enumerate() {
        let cols = rows[0].len();
        let range: Vec<(f64, f64)> = (0..cols)
            .map(|c| rows.iter().fold((f64::MAX, f64::MIN), |(lo, hi), r| (lo.min(r[c]), hi.max(r[c]))))
            .collect();
        for r in rows.iter_mut() {
            for (c, v) in r.iter_mut().enumerate() {
                *v = scale(*v, range[c]);
            }
        }
        input_range[net] = range;
    }
    let target_range =
        std::array::from_fn(|j| joints.iter().fold((f64::MAX, f64::MIN), |(lo, hi), q| (lo.min(q[j]), hi.max(q[j]))));
    DataSet { joints, inputs: raw, input_range, target_range }
}

fn scale(v: f64, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo { (v - lo) / (hi - lo) } else { 0.5 }
}

/// Result of training one net.
#[derive(Debug, Clone, PartialEq)]
pub struct NetResult {
    /// The network's specification.
    pub spec: NetSpec,
    /// Mean squared error on scaled targets: train, test, validation.
    pub mse: [f64; 3],
    /// Root mean squared error on the test third in the joint's unit (mm or deg).
    pub rmse_test: f64,
    /// Largest error on the test third (mm or deg).
    pub max_error_test: f64,
    /// Epochs run and the epoch kept.
    pub epochs: (usize, usize),
    /// The trained network.
    pub net: Mlp,
}

/// Trains the five nets of Table V.3 on `data` for `epochs` epochs each, seeded.
#[must_use]
pub fn train_all(data: &DataSet, epochs: usize, seed: u64) -> Vec<NetResult> {
    let n = data.joints.len();
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = SplitMix64::new(seed);
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let third = n / 3;
    let (train, rest) = order.split_at(third);
    let (test, validation) = rest.split_at(third);
    TABLE_V3
        .iter()
        .enumerate()
        .map(|(j, spec)| {
            let inputs = &data.inputs[j];
            let target = |k: usize| scale(data.joints[k][j], data.target_range[j]);
            let sizes = [inputs[0].len(), spec.hidden[0], spec.hidden[1], 1];
            let mut net = Mlp::new(&sizes, &mut SplitMix64::new(seed ^ (j as u64 + 1)));
            let mut velocity: Vec<Vec<f64>> = net.weights.iter().map(|w| vec![0.0; w.len()]).collect();
            let mse = |net: &Mlp, set: &[usize]| {
                set.iter().map(|&k| (net.predict(&inputs[k]) - target(k)).powi(2)).sum::<f64>() / set.len() as f64
            };
            let mut shuffle = SplitMix64::new(seed.wrapping_add(0x5eed) ^ j as u64);
            let mut sequence = train.to_vec();
            let (mut best, mut best_epoch, mut best_net) = (f64::MAX, 0, net.clone());
            for epoch in 1..=epochs {
                for i in (1..sequence.len()).rev() {
                    let k = (shuffle.next_u64() % (i as u64 + 1)) as usize;
                    sequence.swap(i, k);
                }
                for &k in &sequence {
                    net.train_one(&inputs[k], target(k), spec.learning_rate, spec.momentum, &mut velocity);
                }
                let v = mse(&net, validation);
                if v < best {
                    (best, best_epoch, best_net) = (v, epoch, net.clone());
                }
            }
            let net = best_net;
            let (lo, hi) = data.target_range[j];
            let unit = if j >= 3 { (hi - lo).to_degrees() } else { hi - lo };
            let errors: Vec<f64> = test.iter().map(|&k| (net.predict(&inputs[k]) - target(k)).abs() * unit).collect();
            let rmse_test = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
            let max_error_test = errors.iter().copied().fold(0.0, f64::max);
            NetResult {
                spec: *spec,
                mse: [mse(&net, train), mse(&net, test), best],
                rmse_test,
                max_error_test,
                epochs: (epochs, best_epoch),
                net,
            }
        })
        .collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    #[test]
    fn back_propagation_follows_the_error_gradient() {
        // With no momentum, one step changes each weight by -rate * dE/dw,
        // E = (target - y)^2 / 2; compare with central differences.
        let mut rng = SplitMix64::new(7);
        let net = Mlp::new(&[3, 4, 5, 1], &mut rng);
        let (input, target, rate) = ([0.2, 0.7, 0.4], 0.9, 1e-3);
        let error = |n: &Mlp| 0.5 * (target - n.predict(&input)).powi(2);
        let mut stepped = net.clone();
        let mut velocity: Vec<Vec<f64>> = net.weights.iter().map(|w| vec![0.0; w.len()]).collect();
        stepped.train_one(&input, target, rate, 0.0, &mut velocity);
        for l in 0..net.weights.len() {
            for k in 0..net.weights[l].len() {
                let h = 1e-6;
                let (mut plus, mut minus) = (net.clone(), net.clone());
                plus.weights[l][k] += h;
                minus.weights[l][k] -= h;
                let gradient = (error(&plus) - error(&minus)) / (2.0 * h);
                let change = stepped.weights[l][k] - net.weights[l][k];
                assert!(
                    (change + rate * gradient).abs() < 1e-9,
                    "layer {l} weight {k}: {change} vs {}",
                    -rate * gradient
                );
            }
        }
    }

    #[test]
    fn momentum_adds_the_previous_change() {
        let mut rng = SplitMix64::new(3);
        let mut net = Mlp::new(&[2, 3, 1], &mut rng);
        let mut velocity: Vec<Vec<f64>> = net.weights.iter().map(|w| vec![0.5; w.len()]).collect();
        let mut plain = net.clone();
        let mut zero: Vec<Vec<f64>> = net.weights.iter().map(|w| vec![0.0; w.len()]).collect();
        net.train_one(&[0.1, 0.9], 0.3, 0.2, 0.4, &mut velocity);
        plain.train_one(&[0.1, 0.9], 0.3, 0.2, 0.0, &mut zero);
        for l in 0..net.weights.len() {
            for k in 0..net.weights[l].len() {
                assert!((net.weights[l][k] - plain.weights[l][k] - 0.4 * 0.5).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_data_set_is_the_full_factorial_scaled_to_the_unit_interval() {
        let kin = Kinematics::new(&crate::Machine::builtin("mx330").unwrap(), 100.0);
        let data = factorial_data(&kin);
        assert_eq!(data.joints.len(), 3125);
        for net in &data.inputs {
            assert!(net.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
        }
        assert!((data.target_range[4].1 - 144f64.to_radians()).abs() < 1e-12);
    }
}
