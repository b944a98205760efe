//! The network from the graph's nodes: the Affine and Linear weights, the CubaLIF's decays
//! and gains, the readout and the recurrent loop, in neurotex's discrete form.

use super::reader::{per_neuron, read_array, read_string, Reader};
use super::{Layers, NirFrom};
use crate::snn::{Network, Readout, Reset};

/// Reads the recurrent loop's weights (the Linear or Affine nodes `rec`, in order from the
/// CubaLIF node `lif` back to it: their product is the loop's weight) into `net`, with the
/// CubaLIF's gain per neuron as for its feed-forward input; a bias on the loop is a
/// constant current, added to the hidden biases.
pub(super) fn recurrent_of(
    reader: &Reader,
    rec: &[String],
    lif: &str,
    dt_s: f64,
    net: &mut Network,
) -> Result<(), String> {
    let h = net.hidden;
    // The loop as one (out, in) matrix and bias: each node's applied to the last's output.
    let mut w: Vec<f64> = (0..h * h)
        .map(|k| f64::from(u8::from(k / h == k % h)))
        .collect();
    let mut bias = vec![0.0; h];
    for node in rec {
        let (wn, bn, out, inp) = read_affine(reader, node)?;
        if (out, inp) != (h, h) {
            return Err(format!(
                "node {node}: the recurrent weight is ({out}, {inp}), not ({h}, {h}) for the {h} neurons of {lif}"
            ));
        }
        let row = |o: usize| &wn[o * h..(o + 1) * h];
        w = (0..h * h)
            .map(|k| {
                (row(k / h).iter().enumerate())
                    .map(|(j, x)| x * w[j * h + k % h])
                    .sum()
            })
            .collect();
        bias = (0..h)
            .map(|o| bn[o] + row(o).iter().zip(&bias).map(|(x, b)| x * b).sum::<f64>())
            .collect();
    }
    let (_, _, gain) = lif_of(reader, lif, dt_s, h)?;
    net.w_rec = (0..h * h)
        .map(|k| gain[k % h] * w[(k % h) * h + k / h])
        .collect();
    for (b, (g, extra)) in net.b_in.iter_mut().zip(gain.iter().zip(&bias)) {
        *b += g * extra;
    }
    Ok(())
}

/// An Affine's (or Linear's) weight, `(out, in)` row-major, and bias.
fn read_affine(reader: &Reader, name: &str) -> Result<(Vec<f64>, Vec<f64>, usize, usize), String> {
    let g = reader.node(name)?;
    let (weight, shape) = read_array(&g, "weight", name)?;
    let [out, inp] = shape.as_slice() else {
        return Err(format!(
            "node {name}: the weight has shape {shape:?}, not (out, in)"
        ));
    };
    let (out, inp) = (*out as usize, *inp as usize);
    let bias = match g.dataset("bias") {
        Ok(_) => read_array(&g, "bias", name)?.0,
        Err(_) => vec![0.0; out],
    };
    if bias.len() != out {
        return Err(format!(
            "node {name}: {} biases for {out} outputs",
            bias.len()
        ));
    }
    Ok((weight, bias, out, inp))
}

/// Each neuron's decay `1 - dt/τ`, each strictly between 0 and 1.
fn decays_of(taus: &[f64], dt_s: f64, at: &str, field: &str) -> Result<Vec<f64>, String> {
    let decays: Vec<f64> = taus.iter().map(|t| 1.0 - dt_s / t).collect();
    if let Some(j) = decays.iter().position(|d| !(*d > 0.0 && *d < 1.0)) {
        return Err(format!("node {at}: `{field}` {} s gives the decay {} per step of {dt_s} s; it must lie between 0 and 1 (tau above dt)", taus[j], decays[j]));
    }
    Ok(decays)
}

/// The one decay of a layer's neurons, when they share it (to a relative 1e-9).
fn shared(decays: &[f64]) -> Option<f64> {
    let first = *decays.first()?;
    let tolerance = 1e-9 * first.max(1e-12) + 1e-12;
    decays
        .iter()
        .all(|d| (d - first).abs() <= tolerance)
        .then_some(first)
}

/// The one decay `1 - dt/τ` of a layer's neurons.
fn one_decay(taus: &[f64], dt_s: f64, at: &str, field: &str) -> Result<f64, String> {
    let decays = decays_of(taus, dt_s, at, field)?;
    shared(&decays).ok_or_else(|| {
        format!(
            "node {at}: `{field}` differs between neurons; neurotex's readout has one per layer"
        )
    })
}

/// Each neuron's decays in the CubaLIF node, `(α_h, β_h)`, and the gain each step gives
/// its input on the membrane scaled to a threshold of 1: `(dt/τ_mem) r (dt/τ_syn) w_in /
/// v_threshold`.
type Lif = (Vec<f64>, Vec<f64>, Vec<f64>);

fn lif_of(reader: &Reader, at: &str, dt_s: f64, h: usize) -> Result<Lif, String> {
    let lif = reader.node(at)?;
    let field = |f: &str| per_neuron(&lif, f, at, h);
    let kind = read_string(&lif, "type", &format!("node {at}"))?.concat();
    // A LIF node has no synapse: its current is the step's input (α = 0, gain 1), as
    // snnTorch's `Leaky` and Norse's `LIFBoxCell` step.
    let (alpha, synapse_gain, tau_mem, tau_field) = if kind == "LIF" {
        (vec![0.0; h], vec![1.0; h], field("tau")?, "tau")
    } else {
        let (tau_syn, w_in) = (field("tau_syn")?, field("w_in")?);
        let alpha = decays_of(&tau_syn, dt_s, at, "tau_syn")?;
        let gain = (0..h).map(|j| (dt_s / tau_syn[j]) * w_in[j]).collect();
        (alpha, gain, field("tau_mem")?, "tau_mem")
    };
    let r = field("r")?;
    // `v_reset` may be left out (nir 1.0.4 has no such field; later versions default to 0).
    let v_reset = match lif.dataset("v_reset") {
        Ok(_) => field("v_reset")?,
        Err(_) => vec![0.0; h],
    };
    let (v_leak, v_threshold) = (field("v_leak")?, field("v_threshold")?);
    let beta = decays_of(&tau_mem, dt_s, at, tau_field)?;
    if v_leak.iter().chain(&v_reset).any(|v| *v != 0.0) {
        return Err(format!(
            "node {at}: v_leak and v_reset must be 0 (neurotex's neurons rest and reset at 0)"
        ));
    }
    if v_threshold.iter().any(|v| *v <= 0.0) {
        return Err(format!("node {at}: v_threshold must be positive"));
    }
    let gain: Vec<f64> = (0..h)
        .map(|j| (dt_s / tau_mem[j]) * r[j] * synapse_gain[j] / v_threshold[j])
        .collect();
    Ok((alpha, beta, gain))
}

/// The readout node's decay, and per class the gain each step gives its input and the
/// constant its leak adds: an LI node (`τ dv/dt = v_leak - v + r a`), or a CubaLIF that
/// never fires whose current is the step's input (`tau_syn = dt`; a threshold of at least
/// 1e20), the readout snnTorch and Norse map, or a LIF node that never fires (with
/// [`NirFrom::Snntorch`], snnTorch's `Leaky` output layer: its membrane, read without
/// reset).
fn readout_of(
    reader: &Reader,
    at: &str,
    dt_s: f64,
    c: usize,
    from: NirFrom,
) -> Result<(f64, Vec<f64>, Vec<f64>), String> {
    let g = reader.node(at)?;
    let field = |f: &str| per_neuron(&g, f, at, c);
    let kind = read_string(&g, "type", &format!("node {at}"))?.concat();
    let (tau, r, leak, input_gain) = if kind == "CubaLIF" {
        let tau_syn = field("tau_syn")?;
        if let Some(t) = tau_syn.iter().find(|t| ((*t - dt_s) / dt_s).abs() > 1e-6) {
            return Err(format!("node {at}: a CubaLIF readout needs tau_syn = dt ({dt_s} s), so that its current is the step's input; got {t} s"));
        }
        if let Some(v) = field("v_threshold")?.iter().find(|v| **v < 1e20) {
            return Err(format!(
                "node {at}: a CubaLIF readout must never fire (v_threshold at least 1e20); got {v}"
            ));
        }
        let w_in = field("w_in")?;
        let gain = (0..c).map(|k| (dt_s / tau_syn[k]) * w_in[k]).collect();
        (field("tau_mem")?, field("r")?, field("v_leak")?, gain)
    } else {
        let fires = (kind == "LIF" && from != NirFrom::Snntorch)
            .then(|| field("v_threshold"))
            .transpose()?
            .and_then(|v| v.into_iter().find(|v| *v < 1e20));
        if let Some(v) = fires {
            return Err(format!("node {at}: a LIF readout that fires (v_threshold {v}); neurotex scores a readout's membrane, which a spike would reset, so a LIF readout must never fire (v_threshold at least 1e20); snnTorch's Leaky output layer reads with --nir-from snntorch, as a membrane without reset"));
        }
        (field("tau")?, field("r")?, field("v_leak")?, vec![1.0; c])
    };
    let field_name = if kind == "CubaLIF" { "tau_mem" } else { "tau" };
    let kappa = one_decay(&tau, dt_s, at, field_name)?;
    let gain = (0..c)
        .map(|k| (dt_s / tau[k]) * r[k] * input_gain[k])
        .collect();
    let leak = (0..c).map(|k| (dt_s / tau[k]) * leak[k]).collect();
    Ok((kappa, gain, leak))
}

pub(super) fn network_of(
    reader: &Reader,
    at: &Layers<'_>,
    readout: Readout,
) -> Result<Network, String> {
    let (names, dt_s, dt_ms) = (at.names, at.scale_s, at.dt_ms);
    let (w1, b1, h, n) = read_affine(reader, &names[1])?;
    let (w2, b2, c, h2) = read_affine(reader, &names[3])?;
    let io_width = |name: &str| -> Result<usize, String> {
        let g = reader.node(name)?;
        let (shape, _) = read_array(&g, "shape", name)?;
        Ok(shape.iter().product::<f64>() as usize)
    };
    if io_width(&names[0])? != n {
        return Err(format!(
            "node {}: its shape is not the {n} inputs of {}",
            names[0], names[1]
        ));
    }
    if h2 != h {
        return Err(format!(
            "node {}: {h2} inputs, but {} has {h} neurons",
            names[3], names[2]
        ));
    }
    if io_width(&names[5])? != c {
        return Err(format!(
            "node {}: its shape is not the {c} outputs of {}",
            names[5], names[3]
        ));
    }
    let (alpha, beta, gain) = lif_of(reader, &names[2], dt_s, h)?;
    let (kappa, out_gain, out_leak) = readout_of(reader, &names[4], dt_s, c, at.from)?;
    let tau_ms = |decay: f64| -f64::from(dt_ms) / decay.ln();
    // Neurons that share their decays are a network of shared time constants; others keep
    // their own, the shared constants then those of the layer's mean decays.
    let (shared_alpha, shared_beta) = (shared(&alpha), shared(&beta));
    let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len().max(1) as f64;
    let (a, b) = (
        shared_alpha.unwrap_or(mean(&alpha)),
        shared_beta.unwrap_or(mean(&beta)),
    );
    let (alpha, beta) = match (shared_alpha, shared_beta) {
        (Some(_), Some(_)) => (Vec::new(), Vec::new()),
        _ => (alpha, beta),
    };
    Ok(Network {
        inputs: n,
        hidden: h,
        classes: c,
        dt_ms,
        tau_syn_ms: tau_ms(a),
        tau_mem_ms: tau_ms(b),
        tau_out_ms: tau_ms(kappa),
        readout,
        w_in: (0..n * h)
            .map(|k| gain[k % h] * w1[(k % h) * n + k / h])
            .collect(),
        b_in: (0..h).map(|j| gain[j] * b1[j]).collect(),
        w_out: (0..h * c)
            .map(|k| out_gain[k % c] * w2[(k % c) * h + k / c])
            .collect(),
        b_out: (0..c).map(|k| out_gain[k] * b2[k] + out_leak[k]).collect(),
        w_rec: Vec::new(),
        reset: Reset::Zero,
        target: Default::default(),
        alpha,
        beta,
        travel_mm_s: None,
        adaptation: None,
        delays: Vec::new(),
    })
}
