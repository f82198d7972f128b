"""An independent port of the Solvers' and Generators' observations and of the Generators'
action -> piece mappings, written from docs/engines.md ("Porting a policy") alone, checked
against the golden episodes `arlpcg export-policy` writes beside each graph: every frame's
observation recomputed from its recorded state within 1e-4; the graph (run by onnxruntime on
the recorded observations) choosing the recorded actions (continuous within 1e-5, binary
equal); a Solver's frame 0 where a reset puts it, from the level's start (its glTF `spawn`);
each Solver frame's next block (platform) or road point and centre line ahead (racing) rebuilt
from the level and the recorded positions; and each Generator piece rebuilt from its frame's
action and state within the level file's rounding (1e-3), placed where the next frame's state
has it. It imports nothing of arlpcg.

    python .ci/port-check.py FILE.onnx...   (plain-profile graphs; others are skipped)
"""
import json
import math
import re
import sys

import numpy as np
import onnxruntime as ort

OBSERVATION_TOLERANCE = 1e-4
ACTION_TOLERANCE = 1e-5
# A piece's numbers are stored to 1 mm and 0.001 degree; a port's last digit may round the
# other way where its trigonometry differs in the last bit.
PIECE_TOLERANCE = 1e-3 + 1e-9
# Positions the simulation holds in float32 (a reset's placement), m.
POSITION_TOLERANCE = 1e-4


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


def extra_columns(s):
    """After the game's observation: a Generator's style knobs (the state's `knobs`), then an
    ability-aware agent's `abilities`, each main ability played / ours - 1."""
    extra = list(s.get("knobs", []))
    if "abilities" in s:
        extra += [v / ours - 1 for v, ours in zip(s["abilities"], s["abilities_built_in"])]
    return extra


# --- a reset, from the level's start (glTF `spawn`) -------------------------------------------

def level_start(level):
    """The level's start (position, heading in degrees, start block size or None) from its YAML."""
    m = re.search(r"^start:\n  position:\n  - (\S+)\n  - (\S+)\n  - (\S+)\n  heading: (\S+)\n"
                  r"(?:  size: (\S+)\n)?", level, re.M)
    position = [float(m.group(k)) for k in (1, 2, 3)]
    return position, float(m.group(4)), float(m.group(5)) if m.group(5) else None


def level_segments(level):
    return [tuple(float(x) for x in m.groups()) for m in re.finditer(
        r"^- length: (\S+)\n  curve: (\S+)\n  height: (\S+)$", level, re.M)]


def level_banking(level):
    m = re.search(r"^road:\n(?:  .*\n)*?  banking: (\S+)$", level, re.M)
    return float(m.group(1)) if m else 10.0


def wrap_radians(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def platform_reset_error(episode):
    """Frame 0 against docs/engines.md's reset: the feet on the start block's top within r of its
    centre along and across its heading, turned at most 90 degrees, at rest."""
    s = episode["frames"][0]["state"]
    position, heading, size = level_start(episode["level"])
    blocks = len(re.findall(r"^- distance: ", episode["level"], re.M))
    radius = 0.4  # our character's capsule: a golden Solver's level has no profile
    r = min(max(0.5 * size - radius - 0.5, 0.0), 1.0)
    h = math.radians(heading)
    d = np.array(s["feet"]) - np.array(position)
    along = d[0] * math.cos(h) - d[2] * math.sin(h)
    across = d[0] * math.sin(h) + d[2] * math.cos(h)
    turn = abs(wrap_radians(s["yaw"][0] - h))
    max_steps = math.ceil(np.float32(10.0 + 4.0 * blocks) / np.float32(np.float32(2.0) / np.float32(60.0)))
    errors = [
        max(abs(along) - r, abs(across) - r, 0.0), abs(d[1]), max(turn - math.pi / 2, 0.0),
        float(np.abs(s["velocity"]).max()), abs(s["grounded"][0] - 1), s["steps"][0],
        abs(s["max_steps"][0] - max_steps),
    ]
    return max(errors)


def racing_reset_error(episode):
    """Frame 0 against docs/engines.md's reset: the chassis 1.15 m over the cross-section nearest
    5 m along, at most 1 m to either side along its banked left, turned at most 4 degrees, at rest."""
    s = episode["frames"][0]["state"]
    start, heading, _ = level_start(episode["level"])
    length, curve, rise = level_segments(episode["level"])[0]
    section = cross_sections(start, heading, length, curve, rise)
    k = nearest_along([x[0] for x in section], 5.0)
    _, centre, h = section[k]
    bank = math.radians(min(max(level_banking(episode["level"]) * curve / length, -15.0), 15.0))
    left = np.array([-math.sin(h) * math.cos(bank), -math.sin(bank), -math.cos(h) * math.cos(bank)])
    d = np.array(s["position"]) - np.array(centre) - np.array([0.0, 1.15, 0.0])
    offset = d @ left
    rotation = quaternion_matrix(*s["rotation_xyzw"])
    forward = rotation @ np.array([1.0, 0.0, 0.0])
    turn = abs(wrap_radians(math.atan2(-forward[2], forward[0]) - h))
    errors = [
        float(np.abs(d - offset * left).max()), max(abs(offset) - 1.0, 0.0),
        max(turn - math.radians(4.0), 0.0), float(np.abs(rotation @ [0, 1, 0] - [0, 1, 0]).max()),
        float(np.abs(s["velocity"]).max()), float(np.abs(s["angular_velocity"]).max()),
        float(np.abs(np.array(s["road_point"]) - centre).max()), abs(s["road_heading"][0] - h),
    ]
    return max(errors)


# --- the state a port computes itself -------------------------------------------------------

def level_blocks(level):
    return [tuple(float(x) for x in m.groups()) for m in re.finditer(
        r"^- distance: (\S+)\n  angle: (\S+)\n  size: (\S+)\n  height: (\S+)$", level, re.M)]


def platform_next_block_errors(episode):
    """Each frame's next block rebuilt as docs/engines.md says: the one after the furthest block
    stood on. Returns the frames where the port's differs, and the largest difference."""
    position, heading, size = level_start(episode["level"])
    platforms = [(np.array(position), wrap_degrees(heading), size)]
    for distance, angle, block_size, height in level_blocks(episode["level"]):
        top, h, _ = platforms[-1]
        piece = {"distance": distance, "angle": angle, "size": block_size, "height": height}
        placed = platform_placed({"last_position": top, "last_heading_degrees": [h]}, piece)
        platforms.append((np.array(placed["last_position"]), placed["last_heading_degrees"][0], block_size))
    radius = 0.4  # our character's capsule: a golden Solver's level has no profile
    furthest, wrong, largest = 0, 0, 0.0
    for t, frame in enumerate(episode["frames"]):
        s = frame["state"]
        feet = np.array(s["feet"])
        if t > 0 and s["grounded"][0] == 1:
            for index, (top, h, block_size) in enumerate(platforms):
                d = feet - top
                b = math.radians(h)
                along = d[0] * math.cos(b) - d[2] * math.sin(b)
                across = d[0] * math.sin(b) + d[2] * math.cos(b)
                half = 0.5 * block_size + radius
                if abs(d[1]) < 0.2 and abs(along) <= half and abs(across) <= half:
                    furthest = max(furthest, index)
                    break
        top, _, block_size = platforms[min(furthest + 1, len(platforms) - 1)]
        difference = max(float(np.abs(top - s["next_block_top"]).max()),
                         abs(block_size - s["next_block_size"][0]))
        largest = max(largest, difference)
        wrong += difference > POSITION_TOLERANCE
    return wrong, largest


def racing_road(level):
    """The road's cross-sections (distance along the road, centre, heading in radians), each
    segment's joined to the last of the one before."""
    start, heading, _ = level_start(level)
    sections, origin, s0 = [], start, 0.0
    for length, curve, rise in level_segments(level):
        own = cross_sections(origin, heading, length, curve, rise)
        sections = sections[:-1] + [(s0 + s, c, h) for s, c, h in own]
        origin, h_end = along_segment(origin, math.radians(heading), math.radians(curve) / length,
                                      rise, length, length)
        heading, s0 = math.degrees(h_end), s0 + length
    return sections, s0


def racing_road_errors(episode):
    """Each frame's road point and centre line ahead rebuilt as docs/engines.md says: snapped to
    the road's cross-sections, ahead of the car's along-track point. Returns the frames where
    the port's differ, and the largest difference."""
    sections, road_length = racing_road(episode["level"])
    distances = [x[0] for x in sections]
    nearest = nearest_along(distances, 5.0)
    along = distances[nearest]
    wrong, largest = 0, 0.0
    for t, frame in enumerate(episode["frames"]):
        s = frame["state"]
        p = np.array(s["position"])
        if t > 0:
            window = range(max(nearest - 8, 0), min(nearest + 9, len(sections)))
            nearest = min(window, key=lambda i: (sections[i][1][0] - p[0]) ** 2 + (sections[i][1][2] - p[2]) ** 2)
            s_near, c, h = sections[nearest]
            ahead = (p[0] - c[0]) * math.cos(h) - (p[2] - c[2]) * math.sin(h)
            along = min(max(s_near + ahead, 0.0), road_length)
        points = [sections[nearest_along(distances, along + a)][1] for a in (8, 16, 26, 40, 60)]
        difference = max(
            float(np.abs(np.array(sections[nearest][1]) - s["road_point"]).max()),
            abs(sections[nearest][2] - s["road_heading"][0]),
            float(np.abs(np.concatenate(points) - s["centre_line_ahead"]).max()),
        )
        largest = max(largest, difference)
        wrong += difference > POSITION_TOLERANCE
    return wrong, largest


# --- the Generators' action -> piece --------------------------------------------------------

def unit(a):
    """An action value (float32, as the graph gives it) clipped to [-1, 1]; NaN: 0."""
    a = float(np.float32(a))
    return 0.0 if math.isnan(a) else min(max(a, -1.0), 1.0)


def lin(u, lo, hi):
    return lo + (u + 1.0) * 0.5 * (hi - lo)


def q(x):
    """Rounded to 0.001, halves away from zero."""
    y = x * 1000.0
    r = math.trunc(y)
    if abs(y - r) >= 0.5:
        r += math.copysign(1.0, y)
    return r / 1000.0


def wrap_degrees(a):
    a = math.fmod(a, 360.0)
    a = a + 360.0 if a < 0 else a
    return a - 360.0 if a > 180.0 else a


def bearing_degrees(dx, dz):
    return math.degrees(math.atan2(-dz, dx))


REACH_HEIGHTS = [-2.0, -1.0, 0.0, 1.0, 2.0]


def max_climb(table):
    climb = REACH_HEIGHTS[0]
    for h, gap in zip(REACH_HEIGHTS, table):
        if h < 0:
            continue
        if gap < 1.0:
            break
        climb = h
    return climb


def max_gap(table, height):
    h = min(max(height, REACH_HEIGHTS[0]), max_climb(table))
    i = min(max(k for k, x in enumerate(REACH_HEIGHTS) if x <= h), 3)
    t = (h - REACH_HEIGHTS[i]) / (REACH_HEIGHTS[i + 1] - REACH_HEIGHTS[i])
    return table[i] + t * (table[i + 1] - table[i])


def platform_piece(s, action, rules):
    rule = {k: v[0] for k, v in rules.items() if len(v) == 1}
    p, heading, goal = s["last_position"], s["last_heading_degrees"][0], s["goal"]
    dx, dy, dz = (goal[k] - p[k] for k in range(3))
    distance = q(lin(unit(action[0]), rule["min_distance"], rule["max_distance"]))
    turn = lin(unit(action[1]), -180.0, 180.0)
    sharpest = min(rule["max_turn"], 90.0)
    angle = q(min(max(wrap_degrees(bearing_degrees(dx, dz) - heading + q(turn)), -sharpest), sharpest))
    size = q(lin(unit(action[2]), rule["min_size"], rule["max_size"]))
    height = q(lin(unit(action[3]), rule["min_height"], rule["max_height"]))
    on_course = dy * min(distance / max(math.hypot(dx, dz), 1e-6), 1.0)
    table = rules["reach_table"]
    height = q(min(min(max(on_course + height, rule["min_height"]), rule["max_height"]), max_climb(table)))
    longest = max_gap(table, height) + 0.5 * (s["last_size"][0] + size)
    distance = q(max(min(distance, longest), rule["min_distance"]))
    return {"distance": distance, "angle": angle, "size": size, "height": height}


def platform_placed(s, piece):
    """Where the block goes: the next frame's last_position, last_heading_degrees, last_size."""
    heading = wrap_degrees(s["last_heading_degrees"][0] + piece["angle"])
    h = math.radians(heading)
    p = s["last_position"]
    position = [p[0] + piece["distance"] * math.cos(h), p[1] + piece["height"],
                p[2] - piece["distance"] * math.sin(h)]
    return {"last_position": position, "last_heading_degrees": [heading], "last_size": [piece["size"]]}


def racing_piece(s, action, rules):
    rule = {k: v[0] for k, v in rules.items()}
    end, heading, goal = s["road_end"], s["road_end_heading_degrees"][0], s["goal"]
    dx, dy, dz = (goal[k] - end[k] for k in range(3))
    length = q(lin(unit(action[0]), rule["min_length"], rule["max_length"]))
    bearing = wrap_degrees(bearing_degrees(dx, dz) - heading)
    curve = q(min(max(bearing + rule["curve_offset"] * unit(action[1]), -rule["max_curve"]), rule["max_curve"]))
    on_course = dy * min(length / max(math.hypot(dx, dz), 1e-6), 1.0)
    height = q(min(max(on_course + rule["max_height"] * unit(action[2]), -rule["max_height"]), rule["max_height"]))
    return {"length": length, "curve": curve, "height": height}


def along_segment(origin, heading, curvature, rise, length, s):
    """The centre line s metres into a segment from `origin` heading `heading` radians: point and
    heading (radians)."""
    h = heading + curvature * s
    if abs(curvature) < 1e-12:
        dx, dz = s * math.cos(heading), -s * math.sin(heading)
    else:
        dx = (math.sin(h) - math.sin(heading)) / curvature
        dz = (math.cos(h) - math.cos(heading)) / curvature
    t = s / length
    return [origin[0] + dx, origin[1] + rise * t * t * (3 - 2 * t), origin[2] + dz], h


def cross_sections(origin, heading_degrees, length, curve, rise):
    """One segment's cross-sections: (distance along it, centre, heading in radians)."""
    n = math.ceil(length / 1.0)
    curvature = math.radians(curve) / length
    out = []
    for k in range(n + 1):
        s = length * k / n
        centre, h = along_segment(origin, math.radians(heading_degrees), curvature, rise, length, s)
        out.append((s, centre, h))
    return out


def nearest_along(distances, s):
    after = next((i for i, x in enumerate(distances) if x >= s), len(distances))
    if after == 0:
        return 0
    if after == len(distances):
        return after - 1
    return after - 1 if s - distances[after - 1] < distances[after] - s else after


def racing_placed(s, piece):
    """Where the segment ends: the next frame's road_end and road_end_heading_degrees."""
    length, curve, rise = piece["length"], piece["curve"], piece["height"]
    end, h = along_segment(s["road_end"], math.radians(s["road_end_heading_degrees"][0]),
                           math.radians(curve) / length, rise, length, length)
    return {"road_end": end, "road_end_heading_degrees": [math.degrees(h)]}


PIECES = {"platform": (platform_piece, platform_placed), "racing": (racing_piece, racing_placed)}


def piece_errors(episode):
    """The largest difference of a rebuilt piece from the recorded one, and of where the port
    places it from the next frame's state; the pieces compared."""
    build, place = PIECES[episode["game"]]
    rules = episode["piece_rules"]
    frames = episode["frames"]
    piece_error, place_error, pieces = 0.0, 0.0, 0
    for k, frame in enumerate(frames):
        if frame.get("piece") is None:
            continue
        ported = build(frame["state"], frame["action"], rules)
        recorded = frame["piece"]
        if ported.keys() != recorded.keys():
            raise SystemExit(f"piece {k}: ported {sorted(ported)}, recorded {sorted(recorded)}")
        piece_error = max(piece_error, max(abs(ported[n] - recorded[n]) for n in recorded))
        pieces += 1
        if k + 1 < len(frames):
            following = frames[k + 1]["state"]
            for name, value in place(frame["state"], recorded).items():
                difference = np.array(value) - np.array(following[name])
                if name.endswith("degrees"):
                    difference = np.array([wrap_degrees(x) for x in difference])
                place_error = max(place_error, float(np.abs(difference).max()))
    return piece_error, place_error, pieces


def check(onnx_path):
    sidecar = json.load(open(onnx_path + ".json"))
    if sidecar["profile"] != "plain":
        return None
    episode = json.load(open(onnx_path + ".golden.json"))
    port = PORTS[(episode["game"], episode["role"])]
    aux = episode.get("aux")
    recorded = np.array([f["observation"] for f in episode["frames"]], dtype=np.float64)
    ported = np.array([port(f["state"], aux) + extra_columns(f["state"]) for f in episode["frames"]],
                      dtype=np.float64)
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
    line = (f"{onnx_path}: {len(recorded)} frames ({episode['outcome']}), observation error "
            f"{observation_error:.2e}, action error {action_error:.2e}, binary mismatches "
            f"{binary_mismatches}")
    ok = (observation_error <= OBSERVATION_TOLERANCE and action_error <= ACTION_TOLERANCE
          and binary_mismatches == 0)
    if episode["role"] == "solver":
        reset, derived = {
            "platform": (platform_reset_error, platform_next_block_errors),
            "racing": (racing_reset_error, racing_road_errors),
        }[episode["game"]]
        reset_error = reset(episode)
        wrong, derived_error = derived(episode)
        line += (f", reset error {reset_error:.2e}, {wrong} frames' next block or road points "
                 f"off (largest {derived_error:.2e})")
        ok = ok and reset_error <= POSITION_TOLERANCE and wrong == 0
        pieces = 0
    else:
        piece_error, place_error, pieces = piece_errors(episode)
        line += f", {pieces} pieces: piece error {piece_error:.2e}, placement error {place_error:.2e}"
        ok = ok and pieces > 0 and piece_error <= PIECE_TOLERANCE and place_error <= PIECE_TOLERANCE
    print(line)
    return ok, len(recorded), pieces


def main(paths):
    results = [r for r in (check(p) for p in paths) if r is not None]
    if not results:
        raise SystemExit("no plain-profile graph among the files given")
    if not all(ok for ok, _, _ in results):
        raise SystemExit("the port does not reproduce every golden episode")
    frames = sum(n for _, n, _ in results)
    pieces = sum(p for _, _, p in results)
    print(f"the port reproduces {len(results)} golden episodes ({frames} frames, {pieces} pieces)")


if __name__ == "__main__":
    main(sys.argv[1:])
