"""Checks a .usda written by `formation` with Pixar's USD (PyPI `usd-core`), against the animation
file it came from. Usage: python .ci/check_usd.py flock.usda flock.json [--tolerance M] [--static] [--subframes K]

- the stage opens; USD's validators (the UsdValidation framework behind `usdchecker`, all
  registered validators) report no errors;
- metersPerUnit 1, upAxis Y, timeCodesPerSecond and framesPerSecond = the animation's fps,
  startTimeCode = the file's start_frame (0 when absent) and endTimeCode = the last frame; with
  --subframes K, K time samples a frame (time codes start + k/K);
- one SkelRoot, Skeleton (with the 9 joints of the convention) and SkelAnimation per bird, the
  animation bound to the skeleton, the skinned mesh bound to it with 4 influences a vertex;
- every bird's root transform at every frame matches the JSON positions (x, z, -y) * wingspan_m
  to the tolerance (default 1e-4 m; give the --keys reduced tolerance for reduced files), and the
  wing joints turn over time (UsdSkel computes the joint transforms).
  With --static (a static --bird-model), the wing joints must instead stay still.
Exits 1 on any failure, printing what failed.
"""
import json
import math
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, UsdSkel, UsdValidation

JOINTS = ["body", "body/neck", "body/tail", "body/upper_arm_L", "body/upper_arm_L/hand_L",
          "body/upper_arm_R", "body/upper_arm_R/hand_R", "body/leg_L", "body/leg_R"]


def main():
    args = sys.argv[1:]
    tol = 1e-4
    static = "--static" in args
    if static:
        args.remove("--static")
    subframes = 1
    if "--subframes" in args:
        i = args.index("--subframes")
        subframes = int(args[i + 1])
        del args[i:i + 2]
    if "--tolerance" in args:
        i = args.index("--tolerance")
        tol = float(args[i + 1])
        del args[i:i + 2]
    usda, anim_path = args
    anim = json.load(open(anim_path))
    failed = []

    def check(ok, what):
        if not ok:
            failed.append(what)

    stage = Usd.Stage.Open(usda)
    check(stage is not None, "stage does not open")
    # USD's validators (what usdchecker runs).
    reg = UsdValidation.ValidationRegistry()
    validators = reg.GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(stage)
    counts = {}
    for e in errors:
        t = str(e.GetType()).split(".")[-1]
        counts[t] = counts.get(t, 0) + 1
        if e.GetType() == UsdValidation.ValidationErrorType.Error:
            failed.append("validator %s: %s" % (e.GetName(), e.GetMessage()))
        else:
            print("  %s %s: %s" % (t, e.GetName(), e.GetMessage()))
    print("validators: %d run, findings %s" % (len(validators), counts or "none"))

    fps = anim["fps"]
    n = len(anim["frames"])
    ws = anim["wingspan_m"]
    check(UsdGeom.GetStageMetersPerUnit(stage) == 1.0, "metersPerUnit")
    check(UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y, "upAxis")
    check(stage.GetTimeCodesPerSecond() == fps, "timeCodesPerSecond %s" % stage.GetTimeCodesPerSecond())
    check(stage.GetFramesPerSecond() == fps, "framesPerSecond")
    start = anim.get("start_frame", 0)
    check(stage.GetStartTimeCode() == start, "startTimeCode %s, expected %d" % (stage.GetStartTimeCode(), start))
    check(stage.GetEndTimeCode() == start + n - 1,
          "endTimeCode %s, expected %d" % (stage.GetEndTimeCode(), start + n - 1))

    crowd = stage.GetPrimAtPath("/flock/crowd")
    if crowd and crowd.IsA(UsdGeom.PointInstancer):
        check_instancer(stage, anim, start, failed, check)
        if failed:
            for f in failed[:20]:
                print("FAILED", f)
            sys.exit(1)
        print("OK", usda)
        return

    roots = [p for p in stage.Traverse() if p.IsA(UsdSkel.Root)]
    skels = [p for p in stage.Traverse() if p.IsA(UsdSkel.Skeleton)]
    anims = [p for p in stage.Traverse() if p.IsA(UsdSkel.Animation)]
    meshes = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    birds = anim["birds"]
    print("prims: %d SkelRoot, %d Skeleton, %d SkelAnimation, %d Mesh (birds %d); %s frames at %s fps"
          % (len(roots), len(skels), len(anims), len(meshes), birds, n, fps))
    check(len(roots) == birds and len(skels) == birds and len(anims) == birds and len(meshes) == birds,
          "prim counts")
    names = [p.GetName() for p in roots]
    check(names == sorted(names), "bird names do not sort")

    cache = UsdSkel.Cache()
    frames = anim["frames"]
    worst = 0.0
    for b, root in enumerate(roots):
        skel = UsdSkel.Skeleton(root.GetChild("rig"))
        check(list(skel.GetJointsAttr().Get()) == JOINTS, "%s: joints" % root.GetPath())
        src = UsdSkel.BindingAPI(skel.GetPrim()).GetAnimationSourceRel().GetTargets()
        check(len(src) == 1 and stage.GetPrimAtPath(src[0]).IsA(UsdSkel.Animation),
              "%s: no SkelAnimation bound" % root.GetPath())
        mesh = UsdSkel.BindingAPI(root.GetChild("mesh"))
        check(mesh.GetSkeletonRel().GetTargets() == [skel.GetPath()], "%s: mesh not bound to its rig" % root.GetPath())
        check(mesh.GetJointIndicesPrimvar().GetElementSize() == 4, "%s: jointIndices elementSize" % root.GetPath())
        xf = UsdGeom.Xformable(root)
        keys = stage.GetRootLayer().customLayerData.get("formation", {}).get("keys", "all")
        if b == 0 and keys == "all":
            codes = xf.GetOrderedXformOps()[0].GetAttr().GetTimeSamples()
            want_codes = [start + i / subframes for i in range(subframes * (n - 1) + 1)]
            check(len(codes) == len(want_codes)
                  and max(abs(a - w) for a, w in zip(codes, want_codes)) < 1e-6,
                  "%s: %d time samples, expected %d (%d a frame from %d)"
                  % (root.GetPath(), len(codes), len(want_codes), subframes, start))
        # Every frame for the first and last birds, every 7th frame for the others.
        step = 1 if b in (0, birds - 1) else 7
        for k in range(0, n, step):
            fr = frames[k]
            t = Usd.TimeCode(start + round((fr["t"] - frames[0]["t"]) * fps, 6))
            p = xf.ComputeLocalToWorldTransform(t).ExtractTranslation()
            want = (fr["x"][b] * ws, fr["z"][b] * ws, -fr["y"][b] * ws)
            err = math.sqrt(sum((p[i] - want[i]) ** 2 for i in range(3)))
            worst = max(worst, err)
            if err > tol:
                failed.append("%s frame %d: %.3g m from the JSON" % (root.GetPath(), k, err))
                break
    # The wingbeat: the first bird turns its upper_arm_L (with several bird models, the first
    # bird wearing a model that flaps: the birds are tried in order).
    arm = JOINTS.index("body/upper_arm_L")
    k0 = max(0, n // 2 - 30)
    distinct = 0
    for b, root in enumerate(roots):
        q = cache.GetSkelQuery(UsdSkel.Skeleton(root.GetChild("rig")))
        ys = []
        # 60 frames from the middle of the flight (a take-off begins with the birds
        # sitting, wings folded, not flapping).
        for k in range(k0, min(n, k0 + 60)):
            local = q.ComputeJointLocalTransforms(Usd.TimeCode(start + k))[arm]
            ys.append(round(local.ExtractRotationQuat().GetImaginary()[2], 4))
        distinct = len(set(ys))
        if static or distinct > 10:
            break
    if static:
        check(distinct == 1, "upper_arm_L turns although the model is static")
    else:
        check(distinct > 10, "upper_arm_L does not turn over 60 frames in the middle of the flight")
    print("upper_arm_L of %s: %d distinct rotations over 60 frames mid-flight" % (root.GetName(), distinct))
    print("root vs JSON: worst %.3g m (tolerance %g m)" % (worst, tol))
    if failed:
        for f in failed[:20]:
            print("FAILED", f)
        sys.exit(1)
    print("OK", usda)


def yawed(v, a, phi):
    """v turned by the bird's pitch (nose up, about +X: Rx(a), a = -pitch) and then its heading
    (about +Y: Ry(phi), phi = pi - heading), as the exporter's yaw quaternion does."""
    x, y, z = v[0], v[1] * math.cos(a) - v[2] * math.sin(a), v[1] * math.sin(a) + v[2] * math.cos(a)
    return (x * math.cos(phi) + z * math.sin(phi), y, -x * math.sin(phi) + z * math.cos(phi))


def check_instancer(stage, anim, start, failed, check):
    """A point-instanced crowd (--usd-mode instancer): one PointInstancer, its prototypes posed
    meshes under it, one instance per bird; at 20 frames across the flight every instance within
    1 mm of the JSON's position (x, z, -y) * wingspan_m, orientations unit quaternions, prototype
    indices in range, and the wingbeat visible (the first bird shows several prototypes)."""
    pi = UsdGeom.PointInstancer(stage.GetPrimAtPath("/flock/crowd"))
    protos = pi.GetPrototypesRel().GetTargets()
    birds, frames, ws = anim["birds"], anim["frames"], anim["wingspan_m"]
    n = len(frames)
    check(len(protos) >= 1 and all(stage.GetPrimAtPath(p).IsA(UsdGeom.Mesh) for p in protos),
          "prototypes are not meshes")
    check(len(pi.GetIdsAttr().Get()) == birds, "ids")
    picks = sorted({round(i * (n - 1) / 19) for i in range(20)})
    worst = 0.0
    shown = set()
    # Birds of different sizes (--size-variation): an instance scales its prototype about the
    # root, and the size is taken about the point size_pivot_m below it, so the instance sits
    # (s - 1) * size_pivot_m up the bird's own vertical from the JSON position.
    meta = stage.GetRootLayer().customLayerData.get("formation", {})
    scales_attr = pi.GetScalesAttr().Get()
    scales = [1.0] * birds
    if scales_attr:
        check(len(scales_attr) == birds, "scales: %d for %d birds" % (len(scales_attr), birds))
        scales = [v[0] for v in scales_attr]
        recorded = list(meta.get("bird_scales", []))
        check(len(recorded) == birds and all(abs(a - b) < 1e-6 for a, b in zip(scales, recorded)),
              "instancer scales differ from customLayerData bird_scales")
    pivot = meta.get("size_pivot_m", 0.0)
    bodies = json.loads(meta["body_m"]) if "body_m" in meta else None
    model_of = list(meta.get("bird_model_of", [0] * birds))
    model_of = [int(m) for m in model_of]
    for k in picks:
        t = Usd.TimeCode(start + round((frames[k]["t"] - frames[0]["t"]) * anim["fps"], 6))
        # Positions are relative to the crowd's own translation (the flock's centre).
        xf = UsdGeom.Xformable(pi.GetPrim()).ComputeLocalToWorldTransform(t)
        pos = [xf.Transform(Gf.Vec3d(p)) for p in pi.GetPositionsAttr().Get(t)]
        rot = pi.GetOrientationsAttr().Get(t)
        idx = pi.GetProtoIndicesAttr().Get(t)
        check(len(pos) == birds and len(rot) == birds and len(idx) == birds, "frame %d: array lengths" % k)
        fr = frames[k]
        for b in range(birds):
            want = (fr["x"][b] * ws, fr["z"][b] * ws, -fr["y"][b] * ws)
            # The instance's offset from the bird's root: yaw * s * (body + shift) - q * s * body
            # (body the model's body joint, shift the size's; q the instance's orientation).
            s_b = scales[b]
            body = bodies[model_of[b]] if bodies else (0.0, 0.0, 0.0)
            shift = (0.0, (s_b - 1.0) / s_b * pivot if s_b else 0.0, 0.0)
            a = -(fr["pitch"][b] if "pitch" in fr else 0.0)
            phi = math.pi - fr["heading"][b]
            yaw_part = yawed(tuple(s_b * (body[i] + shift[i]) for i in range(3)), a, phi)
            q = Gf.Rotation(Gf.Quatd(rot[b].GetReal(), Gf.Vec3d(rot[b].GetImaginary())))
            bank_part = q.TransformDir(Gf.Vec3d(*(s_b * v for v in body)))
            want = tuple(want[i] + yaw_part[i] - bank_part[i] for i in range(3))
            err = math.sqrt(sum((pos[b][i] - want[i]) ** 2 for i in range(3)))
            worst = max(worst, err)
            norm = math.sqrt(rot[b].GetReal() ** 2 + sum(v * v for v in rot[b].GetImaginary()))
            if abs(norm - 1) > 3e-3:
                failed.append("frame %d bird %d: orientation of norm %.4f" % (k, b, norm))
            if not 0 <= idx[b] < len(protos):
                failed.append("frame %d bird %d: prototype %d of %d" % (k, b, idx[b], len(protos)))
    # Every frame of the middle second: the first bird flaps through several prototypes (with
    # several bird models, the first bird that shows more than one).
    mid = n // 2
    seen = [set() for _ in range(birds)]
    for k in range(mid, min(n, mid + int(anim["fps"]))):
        t = Usd.TimeCode(start + round((frames[k]["t"] - frames[0]["t"]) * anim["fps"], 6))
        for b, i in enumerate(pi.GetProtoIndicesAttr().Get(t)):
            seen[b].add(i)
    shown = next((s for s in seen if len(s) > 1), seen[0] if seen else set())
    check(len(protos) == 1 or len(shown) > 3, "the first flapping bird shows %d prototypes" % len(shown))
    check(worst <= 1e-3, "instances %.3g m from the JSON" % worst)
    print("instancer: %d prototypes, %d instances (scales %.3f-%.3f), %d frames checked, worst %.3g m, the first flapping bird shows %d poses"
          % (len(protos), birds, min(scales), max(scales), len(picks), worst, len(shown)))


if __name__ == "__main__":
    main()
