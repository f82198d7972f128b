//! Building an ONNX graph: nodes, constants, inputs and outputs, named as they are made.

use super::proto::*;

/// Nodes and constants under construction, each value named `v<k>` until renamed.
#[derive(Default)]
pub(super) struct GraphBuilder {
    pub(super) nodes: Vec<NodeProto>,
    pub(super) initializers: Vec<TensorProto>,
    pub(super) inputs: Vec<ValueInfoProto>,
    pub(super) outputs: Vec<ValueInfoProto>,
    names: usize,
}

impl GraphBuilder {
    fn fresh(&mut self, prefix: &str) -> String {
        self.names += 1;
        format!("{prefix}{}", self.names)
    }

    /// A node of `op` on `inputs`; its one output's name.
    pub(super) fn node(
        &mut self,
        op: &str,
        inputs: &[&str],
        attribute: Vec<AttributeProto>,
    ) -> String {
        let output = self.fresh("v");
        self.nodes.push(NodeProto {
            input: inputs.iter().map(|s| s.to_string()).collect(),
            output: vec![output.clone()],
            name: format!("{op}_{}", self.nodes.len()),
            op_type: op.into(),
            attribute,
        });
        output
    }

    /// Renames the value `from` (the output of the last node that made it) to `to`.
    pub(super) fn rename(&mut self, from: &str, to: &str) {
        for node in &mut self.nodes {
            for name in node.output.iter_mut().chain(node.input.iter_mut()) {
                if name == from {
                    *name = to.to_string();
                }
            }
        }
    }

    pub(super) fn constant_f32(&mut self, dims: &[usize], values: &[f32]) -> String {
        let name = self.fresh("c");
        self.initializers.push(tensor_f32(&name, dims, values));
        name
    }

    /// A constant made by a `Constant` node (graph outputs are node outputs, which every
    /// runtime accepts).
    pub(super) fn constant_node(&mut self, dims: &[usize], values: &[f32]) -> String {
        let value = AttributeProto {
            name: "value".into(),
            t: Some(tensor_f32("", dims, values)),
            r#type: ATTRIBUTE_TENSOR,
            ..Default::default()
        };
        self.node("Constant", &[], vec![value])
    }

    /// Columns `from..to` of a `[batch, n]` value.
    pub(super) fn columns(&mut self, x: &str, from: usize, to: usize) -> String {
        self.node(
            "Slice",
            &[x],
            vec![
                attribute_ints("axes", &[1]),
                attribute_ints("starts", &[from as i64]),
                attribute_ints("ends", &[to as i64]),
            ],
        )
    }

    /// The columns `indices` of a `[batch, n]` value, in that order.
    pub(super) fn gather_columns(&mut self, x: &str, indices: &[i64]) -> String {
        let name = self.fresh("c");
        self.initializers.push(TensorProto {
            dims: vec![indices.len() as i64],
            data_type: INT64,
            name: name.clone(),
            raw_data: indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
        });
        self.node("Gather", &[x, &name], vec![attribute_int("axis", 1)])
    }

    /// `Clip` of opset 6 to 10: the bounds are attributes.
    pub(super) fn clip(&mut self, x: &str, min: f32, max: f32) -> String {
        self.node(
            "Clip",
            &[x],
            vec![attribute_float("min", min), attribute_float("max", max)],
        )
    }
}

fn tensor_f32(name: &str, dims: &[usize], values: &[f32]) -> TensorProto {
    TensorProto {
        dims: dims.iter().map(|&d| d as i64).collect(),
        data_type: FLOAT,
        name: name.into(),
        raw_data: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
    }
}

pub(super) fn attribute_int(name: &str, i: i64) -> AttributeProto {
    AttributeProto {
        name: name.into(),
        i,
        r#type: ATTRIBUTE_INT,
        ..Default::default()
    }
}

fn attribute_ints(name: &str, ints: &[i64]) -> AttributeProto {
    AttributeProto {
        name: name.into(),
        ints: ints.to_vec(),
        r#type: ATTRIBUTE_INTS,
        ..Default::default()
    }
}

fn attribute_float(name: &str, f: f32) -> AttributeProto {
    AttributeProto {
        name: name.into(),
        f,
        r#type: ATTRIBUTE_FLOAT,
        ..Default::default()
    }
}

pub(super) fn entry(key: &str, value: &str) -> StringStringEntryProto {
    StringStringEntryProto {
        key: key.into(),
        value: value.into(),
    }
}

/// A float tensor value; `None` dimensions are the batch.
pub(super) fn value_info(name: &str, dims: &[Option<usize>]) -> ValueInfoProto {
    typed_value_info(name, dims, FLOAT)
}

/// A tensor value of `element` type (an ONNX `TensorProto.DataType`).
pub(super) fn typed_value_info(name: &str, dims: &[Option<usize>], element: i32) -> ValueInfoProto {
    ValueInfoProto {
        name: name.into(),
        r#type: Some(TypeProto {
            tensor_type: Some(TensorTypeProto {
                elem_type: element,
                shape: Some(TensorShapeProto {
                    dim: dims
                        .iter()
                        .map(|d| match d {
                            Some(size) => Dimension {
                                dim_value: Some(*size as i64),
                                dim_param: None,
                            },
                            None => Dimension {
                                dim_value: None,
                                dim_param: Some("batch".into()),
                            },
                        })
                        .collect(),
                }),
            }),
        }),
        doc_string: String::new(),
    }
}
