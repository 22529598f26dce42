//! A compiled model as a C library (`foldsynth compile`): the names, bounds, parameters,
//! output layout and prose that [`crate::compile::aot`] writes into the object, the
//! header and the manifest.

use super::Model;
use super::compiled::{CompiledModel, objective_target};
use crate::compile::aot::{self, Constant, Interface, Parameter, Variable};
use crate::grammar::VarKind;
use serde_json::{Value as Json, json};

/// The interface of `compiled` (the model `model` of the task named `task`) under the
/// symbol prefix `name`, with `modes` (±1 per internal vertex) as the default mode
/// parameters.
pub fn interface(
    task: &str,
    model: &Model,
    compiled: &CompiledModel,
    modes: &[f64],
    name: &str,
) -> Interface {
    let (n, m) = (compiled.n_vars, compiled.n_constraints);
    // Outputs before the gradients: objective, constraints, surface targets' positions.
    let n_out = 1 + m + compiled.n_aux;
    let up = name.to_ascii_uppercase();
    let vars = model
        .free
        .iter()
        .map(|&i| {
            let (lower, upper) = model.var_bounds(i);
            Variable {
                name: model.plan.variables[i].name.clone(),
                lower,
                upper,
            }
        })
        .collect();
    let plan = &model.plan;
    let mut params: Vec<Parameter> = (0..plan.n_modes)
        .zip(modes)
        .map(|(k, &mode)| {
            // The internal vertices that fold by this parameter (an orbit's members).
            let who: Vec<String> = plan
                .internal
                .iter()
                .zip(&plan.modes)
                .filter(|(_, slot)| **slot == k)
                .map(|(&v, _)| format!("v{}", plan.vertices[v].name))
                .collect();
            Parameter {
                name: format!("M{}", k + 1),
                doc: format!("mode of {} (+1 up, -1 down)", who.join(", ")),
                default: mode,
            }
        })
        .collect();
    params.extend(model.times.iter().enumerate().map(|(k, &t)| Parameter {
        name: format!("t{k}"),
        doc: if k == 0 {
            "the driving parameter at t_max (the constraints' state, and the target's if it is at t_max)".into()
        } else {
            "the driving parameter of a target state".into()
        },
        default: t,
    }));
    let outputs = output_names(model, m);
    let objective = if model.area.is_some() {
        "-weight * A, the area term to maximize (the targets' Omega <= threshold is a constraint)"
    } else if model.targets.len() == 1 {
        "w^2 * |X_g(t) - P|^2, the squared distance of the gripping vertex from its target"
    } else {
        "sum over the targets of w * sqrt(|X_g(t) - P|^2 + 1e-18) (Eq. 38)"
    };
    let doc = vec![
        format!(
            "The design model of the graph \"{}\" for task '{}', gripping vertex v{} (candidate {}).",
            model.plan.sequence,
            task,
            model.plan.vertices[model.gripping].name,
            model.candidate + 1
        ),
        String::new(),
        format!("out[0] is the objective, {objective};"),
        format!(
            "the target is met when it is <= {:e} and every constraint is >= 0.",
            objective_target(model)
        ),
        format!(
            "out[1 + k] is constraint k (k < {up}_N_CONSTRAINTS), satisfied when >= 0 (thesis Eq. 31-35)."
        ),
        format!(
            "The objective's gradient is out[{up}_GRADIENT_OFFSET + i], the constraints' Jacobian"
        ),
        format!("out[{up}_JACOBIAN_OFFSET + k * {up}_N_VARS + i] = d g_k / d vars[i]."),
        "params holds the rigid-body modes of the internal vertices, then the values of t".into(),
        "at which the model folds; NAME_default_params() gives those this library was made with."
            .replace("NAME", name),
    ];
    let constants = constants(model, m, n, n_out);
    Interface {
        name: name.to_string(),
        doc,
        vars,
        params,
        outputs,
        constants,
    }
}

/// The names of the outputs before the gradients: the objective, each constraint's label,
/// and the surface targets' positions (`m` constraints).
fn output_names(model: &Model, m: usize) -> Vec<String> {
    let mut outputs = vec!["objective".to_string()];
    outputs.extend((0..m).map(|k| model.constraint_label(k)));
    outputs.extend(
        model
            .targets
            .iter()
            .filter(|t| t.surface().is_some())
            .enumerate()
            .flat_map(|(j, t)| {
                ["x", "y", "z"].map(|c| {
                    format!(
                        "aux {j}: {c} of v{} at t = {} (surface target; its distance is added outside)",
                        model.plan.vertices[t.vertex].name, t.t
                    )
                })
            }),
    );
    outputs
}

/// The library's constants: counts and the offsets of the output layout (`m` constraints,
/// `n` variables, `n_out` outputs before the gradients).
fn constants(model: &Model, m: usize, n: usize, n_out: usize) -> Vec<Constant> {
    let c = |name: &str, value: usize, doc: &str| Constant {
        name: name.into(),
        value,
        doc: doc.into(),
    };
    vec![
        c("n_constraints", m, "constraints g_k >= 0"),
        c(
            "n_modes",
            model.plan.n_modes,
            "mode parameters: params[0 .. N_MODES)",
        ),
        c(
            "n_times",
            model.times.len(),
            "time parameters: params[N_MODES .. N_PARAMS)",
        ),
        c("value_offset", 0, "out[VALUE_OFFSET]: the objective"),
        c(
            "constraints_offset",
            1,
            "out[CONSTRAINTS_OFFSET + k]: constraint k",
        ),
        c(
            "gradient_offset",
            n_out,
            "out[GRADIENT_OFFSET + i]: d objective / d vars[i]",
        ),
        c(
            "jacobian_offset",
            n_out + n,
            "out[JACOBIAN_OFFSET + k*N_VARS + i]: d g_k / d vars[i]",
        ),
    ]
}

/// The manifest: [`aot::manifest`] plus a `model` object (task, graph, candidate,
/// gripping vertex, modes, variables dropped from the optimization and their fixed
/// values, threshold and target, expression counts).
pub fn manifest(
    task: &str,
    model: &Model,
    compiled: &CompiledModel,
    modes: &[f64],
    iface: &Interface,
) -> Json {
    let mut out = aot::manifest(iface, &compiled.compiled.layout);
    let (n, m) = (compiled.n_vars, compiled.n_constraints);
    let n_out = 1 + m + compiled.n_aux;
    let layout = &mut out["layout"];
    layout["objective"] = json!({"offset": 0});
    layout["constraints"] = json!({"offset": 1, "len": m});
    if compiled.n_aux > 0 {
        layout["aux"] = json!({"offset": 1 + m, "len": compiled.n_aux});
    }
    layout["gradient"] = json!({"offset": n_out, "len": n});
    layout["jacobian"] = json!({"offset": n_out + n, "rows": m, "cols": n, "order": "row-major"});
    let rep = &compiled.compiled.report;
    let dropped: Vec<Json> = model
        .plan
        .variables
        .iter()
        .enumerate()
        .filter(|(i, _)| !model.free.contains(i))
        .map(|(i, v)| json!({"name": v.name, "value": model.var_bounds(i).0}))
        .collect();
    out["model"] = json!({
        "task": task,
        "graph": model.plan.sequence,
        "candidate": model.candidate + 1,
        "gripping_vertex": model.plan.vertices[model.gripping].name,
        "internal_vertices": model.plan.internal.iter().map(|&v| model.plan.vertices[v].name).collect::<Vec<_>>(),
        "modes": modes.iter().map(|m| if *m > 0.0 { "up" } else { "down" }).collect::<Vec<_>>(),
        "variable_kinds": model.free.iter().map(|&i| match model.plan.variables[i].kind {
            VarKind::Sector => "sector",
            VarKind::Length => "length",
        }).collect::<Vec<_>>(),
        "fixed_variables": dropped,
        "times": model.times,
        "t_max": model.t_max,
        "targets": model.targets.iter().map(|t| match t.tip_point() {
            Some(p) => json!({"t": t.t, "point": p, "weight": t.weight}),
            None => json!({"t": t.t, "vertex": model.plan.vertices[t.vertex].name, "goal": t.goal, "weight": t.weight}),
        }).collect::<Vec<_>>(),
        "threshold": model.threshold,
        "objective_target": objective_target(model),
        "n_constraints": compiled.n_constraints,
        "counts": {"before": rep.input, "after": rep.simplified, "with_gradient": rep.with_gradients},
    });
    out
}
