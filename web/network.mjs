// A Generator's network in plain JavaScript, for a page without onnxruntime: the actor's layers
// and the observation normalizer as numbers (what `arlpcg view` serves at /generator.json, from
// `web_generator` in src/services/onnx/web.rs), evaluated here. It stands in for the ONNX graph
// of levels.mjs's `GeneratorNetwork` (same sampling, same build rules), so
//
//   import { PlainNetwork } from "./network.mjs";
//   import { PlatformGenerator } from "./levels.mjs";   // racing: RacingGenerator, racing.mjs
//   const kit = await (await fetch("/generator.json")).json();
//   const level = await new PlatformGenerator(PlainNetwork.fromKit(kit, "platform")).build({ seed: 7, aux: -1 });
//
// The arithmetic follows arlpcg's (crates/core/src/rl/normalizer.rs, policy.rs): each value
// normalized in float64, (x - mean) / sqrt(var + 1e-8), then to float32 and clipped to ±clip;
// each layer x·W + b in float32 with ReLU between layers, each dot product summed as candle's
// gemm sums it for one row: a float32 accumulator from 0, input by input in order, each product
// added in one rounding (a fused multiply-add: a float32 product is exact in float64), the bias
// added after. So the means are candle's to the bit, and the levels `generate`'s to the file's
// rounding (300 of 300 per game in .ci/check-js-levels.mjs --plain), where onnxruntime's sums,
// in another order, leave about one level in twenty a rounding step off (docs/engines.md).

import { GeneratorNetwork } from "./levels.mjs";

export class PlainNetwork extends GeneratorNetwork {
  /**
   * @param {{sidecar: object, network: {normalizer: {mean: number[], var: number[], clip: number},
   *          layers: {inputs: number, outputs: number, weight: number[], bias: number[]}[]}}} kit
   * @param {string} game the game the Generator must build for
   */
  static fromKit(kit, game) {
    GeneratorNetwork.check(kit.sidecar, game);
    return new PlainNetwork(kit);
  }

  constructor(kit) {
    super(null, null, null, kit.sidecar);
    const { normalizer, layers } = kit.network;
    if (normalizer.mean.length !== this.observationSize || normalizer.var.length !== this.observationSize) {
      throw new Error(`the normalizer has ${normalizer.mean.length} columns, the observation ${this.observationSize}`);
    }
    this.centre = Float64Array.from(normalizer.mean);
    this.scale = Float64Array.from(normalizer.var, (v) => 1.0 / Math.sqrt(v + 1e-8));
    this.clip = normalizer.clip;
    let width = this.observationSize;
    this.layers = layers.map((layer, k) => {
      if (layer.inputs !== width || layer.weight.length !== layer.inputs * layer.outputs || layer.bias.length !== layer.outputs) {
        throw new Error(`layer ${k}: ${layer.inputs} × ${layer.outputs} does not follow ${width} inputs`);
      }
      width = layer.outputs;
      // Stored output by output (each output's weights side by side), for the sums below.
      const byOutput = new Float32Array(layer.weight.length);
      for (let i = 0; i < layer.inputs; i++) {
        for (let j = 0; j < layer.outputs; j++) byOutput[j * layer.inputs + i] = layer.weight[i * layer.outputs + j];
      }
      return { inputs: layer.inputs, outputs: layer.outputs, byOutput, bias: Float32Array.from(layer.bias) };
    });
    if (width < this.std.length) throw new Error(`the actor has ${width} outputs for ${this.std.length} actions`);
  }

  /** The actor's unclipped means for one raw observation. */
  async means(observation) {
    let h = new Float32Array(this.observationSize);
    for (let i = 0; i < h.length; i++) {
      const x = Math.fround((observation[i] - this.centre[i]) * this.scale[i]);
      h[i] = Math.min(Math.max(x, -this.clip), this.clip);
    }
    this.layers.forEach((layer, k) => {
      const out = new Float32Array(layer.outputs);
      const last = k === this.layers.length - 1;
      const { inputs, byOutput } = layer;
      // An input at 0 (half the ReLU outputs) adds nothing to any sum: skipped.
      const live = new Int32Array(inputs);
      const values = new Float64Array(inputs);
      let count = 0;
      for (let i = 0; i < inputs; i++) {
        if (h[i] !== 0) {
          live[count] = i;
          values[count++] = h[i];
        }
      }
      // Two outputs at a time (each its own sum, in the same order): half the index reads.
      for (let j = 0; j < layer.outputs; j += 2) {
        const pair = j + 1 < layer.outputs;
        const row = j * inputs;
        const next = pair ? row + inputs : row;
        let sum = 0.0;
        let other = 0.0;
        for (let n = 0; n < count; n++) {
          const i = live[n];
          const x = values[n];
          sum = Math.fround(sum + x * byOutput[row + i]);
          other = Math.fround(other + x * byOutput[next + i]);
        }
        const value = Math.fround(sum + layer.bias[j]);
        out[j] = last || value > 0 ? value : 0.0;
        if (pair) {
          const second = Math.fround(other + layer.bias[j + 1]);
          out[j + 1] = last || second > 0 ? second : 0.0;
        }
      }
      h = out;
    });
    return h.subarray(0, this.std.length);
  }
}
