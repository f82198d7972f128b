// A level file as arlpcg writes it (crates/core/src/level/yaml/file.rs; docs/formats.md), read
// into a plain object: the block-style YAML of `arlpcg generate` and hand-written levels like
// levels/hand/staircase.yaml (comments, one-line flow collections such as
// `{distance: 7, angle: 0, size: 5, height: 0}`). Not a YAML parser: anchors, multi-line flow
// collections or block scalars need a real one (then hand its parsed object to
// `platformLevel` or `racingLevel`). Used by platform-solver.mjs and racing-solver.mjs.

/**
 * The document as nested objects, arrays, numbers and strings.
 * @param {string} text
 */
export function readLevelYaml(text) {
  const lines = text
    .split(/\r?\n/)
    .map((l) => l.replace(/(^|\s)#.*$/, "").replace(/\s+$/, ""))
    .filter((l) => l.trim() !== "");
  let pos = 0;
  const indent = (l) => l.length - l.trimStart().length;
  // A one-line value: a flow collection, a number or a string.
  const value = (s) => {
    const t = s.trim();
    if (t.startsWith("{") || t.startsWith("[")) return flow(t);
    if (/^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(t)) return Number(t);
    return t.replace(/^(['"])(.*)\1$/, "$2");
  };
  // `{a: 1, b: [1, 2]}` or `[1, 2]`: split at the top level's commas.
  function flow(t) {
    const inner = t.slice(1, -1);
    const parts = [];
    let depth = 0;
    let from = 0;
    for (let i = 0; i <= inner.length; i++) {
      const c = inner[i];
      if (c === "{" || c === "[") depth++;
      if (c === "}" || c === "]") depth--;
      if ((c === "," && depth === 0) || i === inner.length) {
        if (inner.slice(from, i).trim() !== "") parts.push(inner.slice(from, i).trim());
        from = i + 1;
      }
    }
    if (t.startsWith("[")) return parts.map(value);
    return Object.fromEntries(
      parts.map((p) => {
        const at = p.indexOf(":");
        return [p.slice(0, at).trim(), value(p.slice(at + 1))];
      }),
    );
  }
  // A node whose lines are indented at least `min` (a mapping or a sequence).
  function node(min) {
    if (pos >= lines.length || indent(lines[pos]) < min) return null;
    const at = indent(lines[pos]);
    if (lines[pos].trimStart().startsWith("- ") || lines[pos].trim() === "-") {
      const out = [];
      while (pos < lines.length && indent(lines[pos]) === at && lines[pos].trimStart().startsWith("-")) {
        const rest = lines[pos].trimStart().slice(1);
        if (rest.trim() === "") {
          pos++;
          out.push(node(at + 1));
        } else if (/^\s*[^\s:{[]+:(\s|$)/.test(rest)) {
          // A mapping inside the item: its first key on the dash's line.
          lines[pos] = " ".repeat(at + 1 + (rest.length - rest.trimStart().length)) + rest.trimStart();
          out.push(node(at + 1));
        } else {
          pos++;
          out.push(value(rest));
        }
      }
      return out;
    }
    const out = {};
    while (pos < lines.length && indent(lines[pos]) === at) {
      const m = lines[pos].trim().match(/^([^:]+):(?:\s+(.*))?$/);
      if (!m) throw new Error(`level file: cannot read line "${lines[pos].trim()}"`);
      pos++;
      if (m[2] !== undefined && m[2] !== "") {
        out[m[1]] = value(m[2]);
      } else {
        // A nested node: deeper lines, or a sequence at the same indentation (YAML allows it).
        const next = pos < lines.length ? lines[pos] : "";
        const sameIndentSeq = indent(next) === at && next.trimStart().startsWith("-");
        out[m[1]] = node(sameIndentSeq ? at : at + 1);
      }
    }
    return out;
  }
  return node(0);
}
