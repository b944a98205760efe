//! The graph's shape: its nodes and edges, nested graphs flattened, checked to be the one
//! path neurotex runs with at most one recurrent loop.

use super::reader::{read_string, Reader};
use super::NODES;

/// The nodes along the graph's one path from its Input to its Output, checked to be the
/// six neurotex runs, in order, and the Linear (or Affine) node of a recurrent loop on the
/// CubaLIF node (`lif → rec → lif`), if there is one.
pub(super) fn path_of_nodes(reader: &Reader) -> Result<(Vec<String>, Option<Vec<String>>), String> {
    let (mut kinds, owned) = nodes_and_edges(reader)?;
    for (name, kind) in &kinds {
        if !NODES.iter().any(|(_, k)| *k == kind) && kind != "Linear" && kind != "LIF" {
            return Err(format!("node {name} is a {kind}; neurotex runs Input → Affine/Linear → CubaLIF or LIF → Affine/Linear → LI (or a LIF or CubaLIF that never fires) → Output, with at most one recurrent loop of Linear/Affine nodes on the hidden layer"));
        }
    }
    let mut edges: Vec<(&str, &str)> = owned
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let rec = take_loop(&mut kinds, &mut edges)?;
    let start = kinds
        .iter()
        .filter(|(_, k)| k == "Input")
        .map(|(n, _)| n.clone())
        .collect::<Vec<_>>();
    let [start] = start.as_slice() else {
        return Err(format!(
            "the graph has {} Input nodes; neurotex runs one",
            start.len()
        ));
    };
    let mut path = vec![start.clone()];
    while path.len() < kinds.len() {
        let at = path.last().cloned().unwrap_or_default();
        let next: Vec<&str> = edges.iter().filter(|e| e.0 == at).map(|e| e.1).collect();
        let [next] = next.as_slice() else {
            return Err(format!(
                "node {at} has {} outgoing edges; neurotex runs one feed-forward path",
                next.len()
            ));
        };
        if path.iter().any(|p| p == next) {
            return Err(format!("the edge {at} → {next} makes a loop (a recurrent edge); neurotex runs feed-forward networks"));
        }
        path.push(next.to_string());
    }
    if edges.len() != kinds.len() - 1 {
        return Err(format!(
            "the graph has {} edges for {} nodes; neurotex runs one path without recurrent edges",
            edges.len(),
            kinds.len()
        ));
    }
    let order: Vec<&str> = path
        .iter()
        .map(|n| {
            kinds
                .iter()
                .find(|(m, _)| m == n)
                .map_or("", |(_, k)| k.as_str())
        })
        .collect();
    let want = ["Input", "Affine", "CubaLIF", "Affine", "LI", "Output"];
    for (i, (got, want)) in order.iter().zip(want).enumerate() {
        let fits = *got == want
            || (want == "Affine" && *got == "Linear")
            || (want == "CubaLIF" && *got == "LIF")
            || (want == "LI" && (*got == "CubaLIF" || *got == "LIF"));
        if !fits {
            return Err(format!("node {} is a {got} where neurotex runs a {want} (Input → Affine → CubaLIF or LIF → Affine → LI → Output)", path[i]));
        }
    }
    if order.len() != want.len() {
        return Err(format!("the graph has {} nodes; neurotex runs the six of Input → Affine → CubaLIF → Affine → LI → Output", order.len()));
    }
    Ok((path, rec))
}

/// A graph's nodes `(name, type)` and edges, with a nested graph's nodes in place of its
/// node (named `outer/inner`): snnTorch writes a recurrent layer (`RLeaky`, `RSynaptic`)
/// as a graph `Input → LIF → Output` with a loop `LIF → w_rec → LIF`, which then reads as
/// the loop on a flat graph's hidden layer.
type NodesAndEdges = (Vec<(String, String)>, Vec<(String, String)>);

fn nodes_and_edges(reader: &Reader) -> Result<NodesAndEdges, String> {
    let (kinds, mut edges) = graph_level(reader, &["node"], "")?;
    let mut flat = Vec::new();
    for (name, kind) in kinds {
        if kind != "NIRGraph" {
            flat.push((name, kind));
            continue;
        }
        let (inner, inner_edges) =
            graph_level(reader, &["node", "nodes", &name], &format!("{name}/"))?;
        if let Some((n, _)) = inner.iter().find(|(_, k)| k == "NIRGraph") {
            return Err(format!("node {n} is a graph inside the graph {name}; neurotex reads one level of nesting (snnTorch's recurrent layer)"));
        }
        let is = |n: &str, want: &str| inner.iter().any(|(m, k)| m == n && k == want);
        let entries: Vec<&String> = (inner_edges.iter().filter(|(a, _)| is(a, "Input")))
            .map(|(_, b)| b)
            .collect();
        let exits: Vec<&String> = (inner_edges.iter().filter(|(_, b)| is(b, "Output")))
            .map(|(a, _)| a)
            .collect();
        let mut rewired = Vec::new();
        for (a, b) in edges {
            if b == name {
                rewired.extend(entries.iter().map(|e| (a.clone(), (*e).clone())));
            } else if a == name {
                rewired.extend(exits.iter().map(|x| ((*x).clone(), b.clone())));
            } else {
                rewired.push((a, b));
            }
        }
        rewired.extend(
            (inner_edges.iter())
                .filter(|(a, b)| !is(a, "Input") && !is(b, "Output"))
                .cloned(),
        );
        edges = rewired;
        flat.extend(
            (inner.iter())
                .filter(|(_, k)| k != "Input" && k != "Output")
                .cloned(),
        );
    }
    Ok((flat, edges))
}

/// The nodes and edges of the graph at `path`, their names prefixed with `prefix`.
fn graph_level(reader: &Reader, path: &[&str], prefix: &str) -> Result<NodesAndEdges, String> {
    let at = format!("/{}", path.join("/"));
    let group = reader.group(path)?;
    let nodes = group
        .group("nodes")
        .map_err(|_| format!("{at} has no nodes"))?;
    let names = nodes.groups().map_err(|e| format!("{at}/nodes: {e}"))?;
    let mut kinds = Vec::new();
    for name in &names {
        let full = format!("{prefix}{name}");
        let g = nodes.group(name).map_err(|e| format!("node {full}: {e}"))?;
        let kind = read_string(&g, "type", &format!("node {full}"))?.concat();
        kinds.push((full, kind));
    }
    let flat = read_string(&group, "edges", &at)?;
    if flat.len() % 2 != 0 {
        return Err(format!("the edges of {at} are not pairs"));
    }
    let edges = (flat.chunks(2))
        .map(|e| (format!("{prefix}{}", e[0]), format!("{prefix}{}", e[1])))
        .collect();
    Ok((kinds, edges))
}

/// Takes the one recurrent loop on a CubaLIF node (through one Linear/Affine node, or two
/// in a row as snnTorch's importer needs, each with no other edge) out of the node list
/// and edges, and returns the loop's nodes in order from the CubaLIF.
fn take_loop(
    kinds: &mut Vec<(String, String)>,
    edges: &mut Vec<(&str, &str)>,
) -> Result<Option<Vec<String>>, String> {
    let kind_of = |n: &str| kinds.iter().find(|(m, _)| m == n).map(|(_, k)| k.clone());
    let dense = |n: &str| {
        matches!(kind_of(n).as_deref(), Some("Linear" | "Affine"))
            && edges.iter().filter(|e| e.0 == n || e.1 == n).count() == 2
    };
    let next = |n: &str| edges.iter().find(|e| e.0 == n).map(|e| e.1);
    let mut loops: Vec<(String, Vec<String>)> = Vec::new();
    for &(lif, a) in edges.iter() {
        if !matches!(kind_of(lif).as_deref(), Some("CubaLIF" | "LIF")) || !dense(a) {
            continue;
        }
        let mut path = vec![a.to_string()];
        let mut at = next(a);
        if let Some(b) = at.filter(|&b| b != lif && dense(b)) {
            path.push(b.to_string());
            at = next(b);
        }
        if at == Some(lif) {
            loops.push((lif.to_string(), path));
        }
    }
    Ok(match loops.as_slice() {
        [] => None,
        [(lif, path)] => {
            let on_loop = |n: &str| n == lif || path.iter().any(|p| p == n);
            edges.retain(|e| !(on_loop(e.0) && on_loop(e.1)));
            kinds.retain(|(n, _)| !path.contains(n));
            Some(path.clone())
        }
        _ => return Err(
            "the graph has more than one recurrent loop; neurotex runs one, on its CubaLIF layer"
                .into(),
        ),
    })
}
