// The random streams arlpcg draws a level's goal, start and Generator samples from, bit for bit,
// reimplemented from the algorithms of the Rust crates it is built with (Cargo.lock):
//
// - rand_chacha 0.10.0's ChaCha8Rng: the ChaCha stream cipher (D. J. Bernstein) with 8 rounds,
//   the 32-byte seed as the key, a 64-bit block counter from 0 in words 12-13 and a zero
//   nonce in words 14-15, buffered four blocks (64 words) at a time as rand_core 0.10.1's
//   BlockRng buffers them: a u32 is the next word; a u64 is the next two words, low first (the
//   last word of a buffer and the first of the next when one word is left).
// - rand_core 0.10.1's SeedableRng::seed_from_u64: the 32-byte seed is eight PCG32 outputs
//   (state advanced by the 64-bit LCG first, then XSH-RR), each written little-endian.
// - rand 0.10.3's random_range over f64 (Range and RangeInclusive alike, UniformFloat's
//   sample_single): the u64's top 52 bits as a float in [1, 2), minus 1, times (high - low),
//   plus low.
// - rand_distr 0.6.0's StandardNormal for f32: the f64 ziggurat (Marsaglia and Tsang) over 256
//   layers, its tables as data in ziggurat-normal.mjs, then rounded to f32.
//
// Checked against the crates' own output by .ci/check-js-levels.mjs (through the levels it
// rebuilds) and by web/rng-vectors.json when regenerated (see docs/engines.md).

import { ZIG_NORM_R, ZIG_NORM_X, ZIG_NORM_F } from "./ziggurat-normal.mjs";

const MASK64 = (1n << 64n) - 1n;

// One little-endian scratch double, read and written through its two 32-bit halves.
const scratch = new DataView(new ArrayBuffer(8));
function doubleFromHalves(hi, lo) {
  scratch.setUint32(0, lo >>> 0, true);
  scratch.setUint32(4, hi >>> 0, true);
  return scratch.getFloat64(0, true);
}

/** The top 52 bits of the u64 (hi, lo) as the fraction of a double with the given exponent. */
function fractionWithExponent(hi, lo, exponent) {
  const fracHi = hi >>> 12; // fraction bits 51..32
  const fracLo = ((hi & 0xfff) << 20) | (lo >>> 12); // fraction bits 31..0
  return doubleFromHalves(fracHi | ((1023 + exponent) << 20), fracLo);
}

function rotl(x, n) {
  return (x << n) | (x >>> (32 - n));
}

/** ChaCha8Rng of rand_chacha 0.10, seeded as `ChaCha8Rng::seed_from_u64` or from 32 bytes. */
export class ChaCha8Rng {
  /** @param {Uint8Array} seed 32 bytes, the key. */
  constructor(seed) {
    if (seed.length !== 32) throw new Error("a ChaCha seed is 32 bytes");
    const key = new DataView(seed.buffer, seed.byteOffset, 32);
    this.input = new Uint32Array(16);
    this.input.set([0x61707865, 0x3320646e, 0x79622d32, 0x6b206574]);
    for (let i = 0; i < 8; i++) this.input[4 + i] = key.getUint32(4 * i, true);
    // Words 12 and 13: the block counter (low, high), 14 and 15: the nonce (0).
    this.results = new Uint32Array(64);
    this.index = 64;
    this.work = new Uint32Array(16);
  }

  /** rand_core's `seed_from_u64`: eight PCG32 outputs make the 32-byte seed. */
  static seedFromU64(value) {
    let state = BigInt.asUintN(64, BigInt(value));
    const seed = new Uint8Array(32);
    const view = new DataView(seed.buffer);
    for (let i = 0; i < 8; i++) {
      state = (state * 0x5851f42d4c957f2dn + 0xa17654e46fbe17f3n) & MASK64;
      const xorshifted = Number((((state >> 18n) ^ state) >> 27n) & 0xffffffffn);
      const rot = Number(state >> 59n);
      const x = ((xorshifted >>> rot) | (xorshifted << ((32 - rot) & 31))) >>> 0;
      view.setUint32(4 * i, x, true);
    }
    return new ChaCha8Rng(seed);
  }

  /** Four blocks of 16 words into the buffer, the counter advanced by 4. */
  refill() {
    const x = this.work;
    const input = this.input;
    for (let block = 0; block < 4; block++) {
      x.set(input);
      for (let r = 0; r < 4; r++) {
        // A column round, then a diagonal round: 8 rounds in all.
        quarter(x, 0, 4, 8, 12);
        quarter(x, 1, 5, 9, 13);
        quarter(x, 2, 6, 10, 14);
        quarter(x, 3, 7, 11, 15);
        quarter(x, 0, 5, 10, 15);
        quarter(x, 1, 6, 11, 12);
        quarter(x, 2, 7, 8, 13);
        quarter(x, 3, 4, 9, 14);
      }
      for (let i = 0; i < 16; i++) this.results[16 * block + i] = (x[i] + input[i]) >>> 0;
      input[12] = (input[12] + 1) >>> 0;
      if (input[12] === 0) input[13] = (input[13] + 1) >>> 0;
    }
  }

  /** The next 32-bit word. */
  nextU32() {
    if (this.index >= 64) {
      this.refill();
      this.index = 0;
    }
    return this.results[this.index++];
  }

  /** The next u64 as [hi, lo] 32-bit halves (rand_core's `next_u64_from_u32`). */
  nextU64Halves() {
    let lo;
    let hi;
    if (this.index < 63) {
      lo = this.results[this.index];
      hi = this.results[this.index + 1];
      this.index += 2;
    } else if (this.index === 63) {
      lo = this.results[63];
      this.refill();
      hi = this.results[0];
      this.index = 1;
    } else {
      this.refill();
      lo = this.results[0];
      hi = this.results[1];
      this.index = 2;
    }
    return [hi, lo];
  }

  /** The next u64 as a BigInt (for tests). */
  nextU64() {
    const [hi, lo] = this.nextU64Halves();
    return (BigInt(hi) << 32n) | BigInt(lo);
  }

  /** rand's `random_range(low..high)` and `random_range(low..=high)` for f64 (the same draw). */
  randomRange(low, high) {
    const [hi, lo] = this.nextU64Halves();
    const value01 = fractionWithExponent(hi, lo, 0) - 1.0;
    return value01 * (high - low) + low;
  }

  /** rand's `random::<f64>()` (StandardUniform): the top 53 bits times 2⁻⁵³. */
  randomF64() {
    const [hi, lo] = this.nextU64Halves();
    return (hi * 2097152 + (lo >>> 11)) * 1.1102230246251565e-16;
  }

  /** rand's Open01 for f64: the top 52 bits in [1, 2), minus 1 - ε/2. */
  open01() {
    const [hi, lo] = this.nextU64Halves();
    return fractionWithExponent(hi, lo, 0) - (1.0 - Number.EPSILON / 2);
  }

  /** rand_distr's StandardNormal as f64 (the ziggurat, symmetric). */
  standardNormalF64() {
    for (;;) {
      const [hi, lo] = this.nextU64Halves();
      const i = lo & 0xff;
      // The top 52 bits in [2, 4), minus 3: [-1, 1).
      const u = fractionWithExponent(hi, lo, 1) - 3.0;
      const x = u * ZIG_NORM_X[i];
      if (Math.abs(x) < ZIG_NORM_X[i + 1]) return x;
      if (i === 0) return this.normalTail(u);
      const f1 = ZIG_NORM_F[i + 1];
      if (f1 + (ZIG_NORM_F[i] - f1) * this.randomF64() < Math.exp((-x * x) / 2.0)) return x;
    }
  }

  /** The ziggurat's base layer: a draw beyond R by Marsaglia's tail method. */
  normalTail(u) {
    let x = 1.0;
    let y = 0.0;
    while (-2.0 * y < x * x) {
      const x1 = this.open01();
      const y1 = this.open01();
      x = Math.log(x1) / ZIG_NORM_R;
      y = Math.log(y1);
    }
    return u < 0.0 ? x - ZIG_NORM_R : ZIG_NORM_R - x;
  }

  /** rand_distr's StandardNormal for f32: the f64 draw rounded to f32. */
  standardNormalF32() {
    return Math.fround(this.standardNormalF64());
  }
}

function quarter(x, a, b, c, d) {
  x[a] = (x[a] + x[b]) >>> 0;
  x[d] = rotl(x[d] ^ x[a], 16) >>> 0;
  x[c] = (x[c] + x[d]) >>> 0;
  x[b] = rotl(x[b] ^ x[c], 12) >>> 0;
  x[a] = (x[a] + x[b]) >>> 0;
  x[d] = rotl(x[d] ^ x[a], 8) >>> 0;
  x[c] = (x[c] + x[d]) >>> 0;
  x[b] = rotl(x[b] ^ x[c], 7) >>> 0;
}
