// An exported graph with its Gaussian means as one more output: the actor's output before the
// clip to [-1, 1] that gives `continuous_actions` (arlpcg's export writes that clip as the last
// node of the continuous actions). Sampling as arlpcg samples needs the unclipped mean (a mean
// beyond ±1 plus noise is not the clipped mean plus noise), and the graph does not output it, so
// the bytes are edited before the graph is loaded: the node is found by its output's name and
// an output named after its input is appended to the graph. Only the protobuf wire format is
// read (ModelProto.graph = 7; GraphProto.node = 1, output = 12; NodeProto.input = 1,
// output = 2, op_type = 4; ValueInfoProto.name = 1, type = 2; TypeProto.tensor_type = 1;
// Tensor.elem_type = 1, FLOAT = 1); nothing else in the graph changes.

function readVarint(bytes, pos) {
  let value = 0;
  let scale = 1;
  for (;;) {
    const b = bytes[pos++];
    value += (b & 0x7f) * scale;
    if (b < 0x80) return [value, pos];
    scale *= 128;
  }
}

function varint(value) {
  const out = [];
  while (value >= 0x80) {
    out.push((value % 128) | 0x80);
    value = Math.floor(value / 128);
  }
  out.push(value);
  return out;
}

/** Each field of a message: its number, wire type, where it starts and its payload's bounds. */
function* fields(bytes, start = 0, end = bytes.length) {
  let pos = start;
  while (pos < end) {
    const begin = pos;
    let key;
    [key, pos] = readVarint(bytes, pos);
    const field = Math.floor(key / 8);
    const wire = key % 8;
    let from = pos;
    if (wire === 0) {
      [, pos] = readVarint(bytes, pos);
    } else if (wire === 1) {
      pos += 8;
    } else if (wire === 2) {
      let length;
      [length, from] = readVarint(bytes, pos);
      pos = from + length;
    } else if (wire === 5) {
      pos += 4;
    } else {
      throw new Error(`unsupported protobuf wire type ${wire}`);
    }
    yield { field, wire, begin, from, to: pos };
  }
}

const utf8 = new TextDecoder();
const encoder = new TextEncoder();

function concat(parts) {
  const out = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
}

function field(number, payload) {
  return concat([new Uint8Array([...varint(number * 8 + 2), ...varint(payload.length)]), payload]);
}

/**
 * The graph's bytes with the unclipped means of `continuous_actions` as an output too, and that
 * output's name. With `skipNormalizer`, the first layer reads the graph's input directly (the
 * normalizer's nodes left unused), for a caller that normalizes as arlpcg does, in float64.
 * @param {Uint8Array} model the .onnx file's bytes
 * @returns {{bytes: Uint8Array, meanOutput: string}}
 */
export function exposeMeans(model, { skipNormalizer = false, clippedName = "continuous_actions" } = {}) {
  const graph = [...fields(model)].find((f) => f.field === 7 && f.wire === 2);
  if (!graph) throw new Error("not an ONNX model: no graph");
  const text = (g) => utf8.decode(model.subarray(g.from, g.to));
  let meanOutput = null;
  let input = null;
  const nodes = [];
  const parts = [];
  for (const f of fields(model, graph.from, graph.to)) {
    if (f.field === 11 && f.wire === 2 && input === null) {
      input = text([...fields(model, f.from, f.to)].find((g) => g.field === 1));
    }
    if (f.field !== 1 || f.wire !== 2) {
      parts.push(model.subarray(f.begin, f.to));
      continue;
    }
    const node = { input: [], output: [], op: "", firstInput: null, f };
    for (const g of fields(model, f.from, f.to)) {
      if (g.field === 1) {
        node.input.push(text(g));
        node.firstInput ??= g;
      }
      if (g.field === 2) node.output.push(text(g));
      if (g.field === 4) node.op = text(g);
    }
    if (node.op === "Clip" && node.output[0] === clippedName) meanOutput = node.input[0];
    nodes.push(node);
    parts.push(node);
  }
  if (meanOutput === null) {
    throw new Error(`no Clip node gives ${clippedName}: not a graph of arlpcg export-policy`);
  }
  // The normalizer's last node: the Clip the graph's input reaches through Sub and Mul.
  const producer = new Map(nodes.flatMap((n) => n.output.map((o) => [o, n])));
  const firstLayer = nodes.find((n) => n.op === "Gemm" && producer.get(n.input[0])?.op === "Clip");
  const content = parts.map((p) => {
    if (p instanceof Uint8Array) return p;
    if (!(skipNormalizer && p === firstLayer)) return model.subarray(p.f.begin, p.f.to);
    const g = p.firstInput;
    const body = concat([
      model.subarray(p.f.from, g.begin),
      field(1, encoder.encode(input)),
      model.subarray(g.to, p.f.to),
    ]);
    return field(1, body);
  });
  if (skipNormalizer && !firstLayer) throw new Error("no normalizer before the first layer");
  // output { name: meanOutput, type { tensor_type { elem_type: FLOAT } } }
  const valueInfo = concat([
    field(1, encoder.encode(meanOutput)),
    field(2, field(1, new Uint8Array([0x08, 0x01]))),
  ]);
  content.push(field(12, valueInfo));
  const edited = concat([model.subarray(0, graph.begin), field(7, concat(content)), model.subarray(graph.to)]);
  return { bytes: edited, meanOutput };
}
