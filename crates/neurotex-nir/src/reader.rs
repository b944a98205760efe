//! Reading a graph's HDF5 file: its groups and numeric arrays, each checked finite, and
//! the time its constants are read against.

use hdf5_pure::{DType, File};

use super::{NirFrom, SNNTORCH_DT_S};

/// The graph's arrays, read as f64.
pub(super) struct Reader {
    pub(super) file: File,
}

impl Reader {
    pub(super) fn group(&self, path: &[&str]) -> Result<hdf5_pure::Group, String> {
        let mut g = self.file.root();
        let mut at = String::new();
        for name in path {
            at.push('/');
            at.push_str(name);
            g = g
                .group(name)
                .map_err(|_| format!("the graph has no group {at}"))?;
        }
        Ok(g)
    }

    /// The group of node `name`; `outer/inner` names a node of the subgraph `outer`.
    pub(super) fn node(&self, name: &str) -> Result<hdf5_pure::Group, String> {
        let mut path = vec!["node"];
        for part in name.split('/') {
            path.extend(["nodes", part]);
        }
        self.group(&path)
    }
}

pub(super) fn read_string(
    g: &hdf5_pure::Group,
    name: &str,
    at: &str,
) -> Result<Vec<String>, String> {
    let ds = g
        .dataset(name)
        .map_err(|_| format!("{at} has no `{name}`"))?;
    ds.read_string()
        .map_err(|e| format!("{at}/{name} is not a string: {e}"))
}

pub(super) fn read_array(
    g: &hdf5_pure::Group,
    name: &str,
    at: &str,
) -> Result<(Vec<f64>, Vec<u64>), String> {
    let ds = g
        .dataset(name)
        .map_err(|_| format!("node {at} has no `{name}`"))?;
    let shape = ds.shape().map_err(|e| format!("node {at}: {name}: {e}"))?;
    let numeric = matches!(
        ds.dtype(),
        Ok(DType::F32 | DType::F64 | DType::I32 | DType::I64)
    );
    if !numeric {
        return Err(format!("node {at}: `{name}` is not a numeric array"));
    }
    let values = ds
        .read_f64()
        .map_err(|e| format!("node {at}: {name}: {e}"))?;
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "node {at}: `{name}`[{i}] is not finite ({})",
            values[i]
        ));
    }
    Ok((values, shape))
}

/// A number in the graph's metadata, if it has the field.
pub(super) fn meta_number(
    meta: Option<&hdf5_pure::Group>,
    field: &str,
) -> Result<Option<f64>, String> {
    let Some(d) = meta.and_then(|m| m.dataset(field).ok()) else {
        return Ok(None);
    };
    let v = d.read_f64().map_err(|_| {
        format!("the graph's metadata `{field}` is not a number (a time step in seconds)")
    })?;
    match v.first() {
        Some(&x) if x > 0.0 && x.is_finite() => Ok(Some(x)),
        Some(x) => Err(format!(
            "the graph's metadata `{field}` is {x}; a time step must be positive"
        )),
        None => Err(format!("the graph's metadata `{field}` is empty")),
    }
}

/// The time against which the graph's constants are read (every formula has `dt/τ`) and
/// the network's step, both in seconds. NIR's graphs say `dt`; neurotex's graphs for
/// snnTorch keep the network's own step as `neurotex_dt` beside snnTorch's `dt`; snnTorch
/// writes its constants for 1e-4 s and Norse its time constants multiplied by the step,
/// and neither says the step, which then is the `--like` model's.
pub(super) fn time_of(
    meta: Option<&hdf5_pure::Group>,
    from: NirFrom,
    fallback_step_s: Option<f64>,
) -> Result<(f64, f64), String> {
    let dt = meta_number(meta, "dt")?;
    let own_step = meta_number(meta, "neurotex_dt")?;
    let no_step = |tool: &str| {
        format!("the graph's metadata has no `dt` (its time step in seconds), as {tool} writes none: give the neurotex spiking model whose pipeline makes its input spikes (--like MODEL.json), whose dt_ms is the step")
    };
    match from {
        NirFrom::Nir => {
            let dt = dt.or(fallback_step_s).ok_or_else(|| {
                "the graph's metadata has no `dt` (its time step in seconds)".to_string()
            })?;
            Ok((dt, own_step.unwrap_or(dt)))
        }
        NirFrom::Snntorch => {
            let step = own_step
                .or(fallback_step_s)
                .ok_or_else(|| no_step("snnTorch"))?;
            Ok((SNNTORCH_DT_S, step))
        }
        NirFrom::Norse => {
            let step = dt.or(fallback_step_s).ok_or_else(|| no_step("Norse"))?;
            Ok((step * step, step))
        }
    }
}

/// One value per neuron of a layer of `len` (a single value applies to all).
pub(super) fn per_neuron(
    g: &hdf5_pure::Group,
    field: &str,
    at: &str,
    len: usize,
) -> Result<Vec<f64>, String> {
    let (values, _) = read_array(g, field, at)?;
    match values.len() {
        1 => Ok(vec![values[0]; len]),
        n if n == len => Ok(values),
        n => Err(format!(
            "node {at}: `{field}` has {n} values for {len} neurons"
        )),
    }
}
