"""An independent port of the Solvers' and Generators' observations, written from
docs/engines.md ("Porting a policy") alone, checked against the golden episodes `arlpcg
export-policy` writes beside each graph: every frame's observation recomputed from its recorded state within 1e-4, and
the graph (run by onnxruntime on the recorded observations) choosing the recorded actions
(continuous within 1e-5, binary equal). It imports nothing of arlpcg.

    python .ci/port-check.py FILE.onnx...   (plain-profile graphs; others are skipped)
"""
import json
import math
import sys

import numpy as np
import onnxruntime as ort

OBSERVATION_TOLERANCE = 1e-4
ACTION_TOLERANCE = 1e-5


def rotate_y(angle, v):
    """Rotation about +Y (right-handed, Y up) by `angle` radians."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([v[0] * c + v[2] * s, v[1], -v[0] * s + v[2] * c])


def quaternion_matrix(x, y, z, w):
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def platform_observation(s):
    feet = np.array(s["feet"])
    yaw = s["yaw"][0]
    forward = np.array([math.cos(yaw), 0.0, -math.sin(yaw)])
    left = np.array([forward[2], 0.0, -forward[0]])

    def local(u):
        return [u @ forward, u[1], u @ left]

    to_goal = np.array(s["goal"]) - feet
    to_next = np.array(s["next_block_top"]) - feet
    bearing = math.atan2(to_next @ left, to_next @ forward)
    obs = [x / 50 for x in local(to_goal)]
    obs.append(np.linalg.norm(to_goal) / 50)
    obs += [x / 10 for x in local(to_next)]
    obs.append(s["next_block_size"][0] / 6)
    obs += [x / 10 for x in local(np.array(s["velocity"]))]
    obs += [math.sin(bearing), math.cos(bearing)]
    obs.append(s["grounded"][0])
    obs.append(1 - s["steps"][0] / s["max_steps"][0])
    obs += [(2.2 - d) / 4 for d in s["height_map_hits"]]
    return obs


def racing_observation(s):
    p = np.array(s["position"])
    rotation = quaternion_matrix(*s["rotation_xyzw"])
    into_car = rotation.T
    forward = rotation @ np.array([1.0, 0.0, 0.0])
    yaw = math.atan2(-forward[2], forward[0])

    def into_level(u):
        return rotate_y(-yaw, u)

    goal = into_level(np.array(s["goal"]) - p)
    bearing = math.atan2(-goal[2], goal[0])
    heading = s["road_heading"][0]
    road_bearing = heading - yaw
    centre = np.array(s["road_point"])
    lateral = -(p[0] - centre[0]) * math.sin(heading) - (p[2] - centre[2]) * math.cos(heading)
    obs = list(goal / 100)
    obs += [math.sin(bearing), math.cos(bearing)]
    obs += list(into_car @ np.array(s["velocity"]) / 20)
    obs += list(into_car @ np.array(s["angular_velocity"]))
    obs += list(into_car @ np.array([0.0, 1.0, 0.0]))
    obs.append(lateral / 4.5)
    obs += [math.sin(road_bearing), math.cos(road_bearing)]
    ahead = s["centre_line_ahead"]
    for k in range(0, len(ahead), 3):
        u = into_level(np.array(ahead[k:k + 3]) - p)
        obs += [u[0] / 60, u[2] / 20]
    obs += [(6 - d) / 6 for d in s["fan_hits"]]
    return obs


def plan_local(d, heading_degrees):
    """`d` in the frame of a heading: forward, up, left (a positive turn)."""
    h = math.radians(heading_degrees)
    fx, fz = math.cos(h), -math.sin(h)
    return [d[0] * fx + d[2] * fz, d[1], d[0] * fz - d[2] * fx]


def platform_generator_observation(s, aux):
    p = s["last_position"]
    heading = s["last_heading_degrees"][0]

    def local(point):
        return plan_local([point[k] - p[k] for k in range(3)], heading)

    g = local(s["goal"])
    bearing = math.atan2(g[2], g[0])
    obs = [x / 50 for x in g] + [math.sin(bearing), math.cos(bearing), math.hypot(g[0], g[2]) / 50]
    obs.append(s["last_size"][0] / 6)
    previous = s["previous_position_size"]
    obs += [x / 10 for x in local(previous[:3])] if previous else [0.0] * 3
    obs.append(previous[3] / 6 if previous else 0.0)
    turn = math.radians(s["last_turn_degrees"][0]) if s["last_turn_degrees"] else 0.0
    obs += [math.sin(turn), math.cos(turn)]
    obs.append(1 - s["blocks"][0] / s["max_blocks"][0])
    return obs + [aux]


def racing_generator_observation(s, aux):
    end = s["road_end"]
    heading = s["road_end_heading_degrees"][0]
    g = plan_local([s["goal"][k] - end[k] for k in range(3)], heading)
    bearing = math.atan2(g[2], g[0])
    obs = [x / 100 for x in g] + [math.sin(bearing), math.cos(bearing), math.hypot(g[0], g[2]) / 300]
    obs += [math.sin(math.radians(heading)), math.cos(math.radians(heading))]
    last = s["last_segment"]
    obs += [(last[0] - 20) / 10 * 2 - 1, last[1] / 30, last[2] / 5] if last else [0.0] * 3
    obs.append(1 - s["segments"][0] / s["max_segments"][0])
    return obs + s["obstacle_rays"] + s["road_rays"] + [aux]


PORTS = {
    ("platform", "solver"): lambda s, aux: platform_observation(s),
    ("racing", "solver"): lambda s, aux: racing_observation(s),
    ("platform", "generator"): platform_generator_observation,
    ("racing", "generator"): racing_generator_observation,
}


def abilities(sidecar, episode):
    """An ability-aware Solver's last columns (`abilities`): the profile's main abilities, each
    as value / ours - 1. A golden episode's level records no profile (our character): all 0."""
    columns = next(i for i in sidecar["inputs"] if i["name"] == "observation")["columns"]
    last = columns[-1]
    if last["name"] != "abilities":
        return []
    if "\nprofile:" in episode["level"]:
        raise SystemExit("a golden episode under a profile: port its abilities")
    return [0.0] * last["width"]


def check(onnx_path):
    sidecar = json.load(open(onnx_path + ".json"))
    if sidecar["profile"] != "plain":
        return None
    episode = json.load(open(onnx_path + ".golden.json"))
    port = PORTS[(episode["game"], episode["role"])]
    aux = episode.get("aux")
    extra = abilities(sidecar, episode)
    recorded = np.array([f["observation"] for f in episode["frames"]], dtype=np.float64)
    ported = np.array([port(f["state"], aux) + extra for f in episode["frames"]], dtype=np.float64)
    if ported.shape != recorded.shape:
        raise SystemExit(f"{onnx_path}: ported {ported.shape}, recorded {recorded.shape}")
    observation_error = float(np.abs(ported - recorded).max())
    session = ort.InferenceSession(onnx_path, providers=["CPUExecutionProvider"])
    outputs = dict(zip(
        [o.name for o in session.get_outputs()],
        session.run(None, {"observation": recorded.astype(np.float32)}),
    ))
    actions = np.array([f["action"] for f in episode["frames"]], dtype=np.float64)
    continuous = outputs["continuous_actions"].shape[1]
    action_error = float(np.abs(outputs["continuous_actions"] - actions[:, :continuous]).max())
    binary_mismatches = 0
    if "binary_actions" in outputs:
        binary_mismatches = int((outputs["binary_actions"] != actions[:, continuous:]).sum())
    print(f"{onnx_path}: {len(recorded)} frames ({episode['outcome']}), observation error "
          f"{observation_error:.2e}, action error {action_error:.2e}, binary mismatches "
          f"{binary_mismatches}")
    return (observation_error <= OBSERVATION_TOLERANCE and action_error <= ACTION_TOLERANCE
            and binary_mismatches == 0)


def main(paths):
    results = [r for r in (check(p) for p in paths) if r is not None]
    if not results:
        raise SystemExit("no plain-profile graph among the files given")
    if not all(results):
        raise SystemExit("the port does not reproduce every golden episode")
    print(f"the port reproduces {len(results)} golden episodes")


if __name__ == "__main__":
    main(sys.argv[1:])
