"""Checks exported policies with the ONNX project's own tools: the `onnx` checker (full check,
shapes inferred) and onnxruntime, which runs each graph on its sidecar's example rows and must
give the outputs this tool computed for them (max abs error < 1e-4).

    python check-onnx.py FILE.onnx...   (each with FILE.onnx.json beside it)
"""

import json
import sys

import numpy as np
import onnx
import onnxruntime

TOLERANCE = 1e-4


def check(path):
    model = onnx.load(path)
    onnx.checker.check_model(model, full_check=True)
    with open(path + ".json") as f:
        sidecar = json.load(f)
    session = onnxruntime.InferenceSession(path, providers=["CPUExecutionProvider"])
    observations = np.array(sidecar["examples"]["observations"], dtype=np.float32)
    feeds = {}
    for port in sidecar["inputs"]:
        if port["name"] == "action_masks":
            feeds["action_masks"] = np.ones((len(observations), port["shape"][1]), np.float32)
        else:
            feeds[port["name"]] = observations
    names = [o.name for o in session.get_outputs()]
    results = dict(zip(names, session.run(names, feeds)))
    worst = 0.0
    for name, expected in sidecar["examples"]["outputs"].items():
        error = float(np.max(np.abs(results[name] - np.array(expected, dtype=np.float32))))
        worst = max(worst, error)
        if not error < TOLERANCE:
            raise SystemExit(f"{path}: output {name} is off by {error} (tolerance {TOLERANCE})")
    for port in sidecar["outputs"]:
        expected_type = np.int64 if port.get("element_type") == "int64" else np.float32
        if results[port["name"]].dtype != expected_type:
            raise SystemExit(f"{path}: output {port['name']} is {results[port['name']].dtype}")
    if sidecar["profile"] == "mlagents":
        for name in ["discrete_actions", "deterministic_discrete_actions"]:
            if name in results and results[name].dtype != np.int64:
                raise SystemExit(f"{path}: ML-Agents' {name} must be int64")
        if results["version_number"].tolist() != [3.0] or results["memory_size"].tolist() != [0.0]:
            raise SystemExit(f"{path}: ML-Agents version_number/memory_size are not [3]/[0]")
    print(f"{path}: checker passed, onnxruntime {onnxruntime.__version__} max abs error {worst:.2e}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    for path in sys.argv[1:]:
        check(path)
