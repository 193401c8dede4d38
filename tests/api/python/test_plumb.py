# The Python module: tracking from NumPy arrays, the same poses as `plumb run` (byte-identical
# trajectory files), evaluation equal to `plumb eval`, and bad arrays raising instead of crashing.
import json
import os
import subprocess

import pytest

np = pytest.importorskip("numpy")
plumb = pytest.importorskip("plumb")


def synthetic_frames(spec):
    reader = plumb.FrameReader(spec)
    return reader, list(reader)


def test_track_synthetic_scene_from_numpy():
    reader, frames = synthetic_frames("synth:textured:2:40")
    assert len(frames) == 40
    rgb, depth, _ = frames[0]
    assert rgb.dtype == np.uint8 and rgb.shape == (480, 640, 3)
    assert depth.dtype == np.uint16 and depth.shape == (480, 640)
    odo = plumb.Odometry(camera=reader.camera)
    states, finished = [], []
    for rgb, depth, t in frames:
        r = odo.track(rgb, depth, t)
        states.append(r.state)
        assert r.pose.shape == (4, 4) and r.pose.dtype == np.float64
        assert np.allclose(r.pose[3], [0, 0, 0, 1])
        assert np.allclose(r.pose[:3, :3] @ r.pose[:3, :3].T, np.eye(3), atol=1e-9)
        if r.covariance is not None:
            assert r.covariance.shape == (6, 6)
            assert np.allclose(r.covariance, r.covariance.T)
            assert np.all(np.linalg.eigvalsh(r.covariance) > 0)
        finished += odo.finished()
    odo.finish()
    finished += odo.finished()
    assert states.count("ok") == 40
    assert len(finished) == 40
    counters = odo.counters
    assert counters["frames"] == 40 and counters["map_segments"] == 1 and counters["relocalizations"] == 0
    est = {"timestamps": np.array([t for t, _ in finished]), "poses": np.stack([T for _, T in finished])}
    result = plumb.evaluate(reader.ground_truth(40), est)
    assert result["ate"]["pairs"] == 40
    assert result["ate"]["rmse"] < 0.02


def test_bad_arrays_raise_with_a_message():
    odo = plumb.Odometry(camera="tum1")
    rgb = np.zeros((480, 640, 3), np.uint8)
    depth = np.zeros((480, 640), np.uint16)
    with pytest.raises(TypeError, match="rgb must be a numpy array of dtype uint8, got dtype float32"):
        odo.track(rgb.astype(np.float32), depth, 0.0)
    with pytest.raises(TypeError, match="dtype uint8"):
        odo.track(rgb.astype(np.uint16), depth, 0.0)
    with pytest.raises(TypeError, match="depth must be a numpy array of dtype uint16"):
        odo.track(rgb, depth.astype(np.float32), 0.0)
    with pytest.raises(TypeError, match="dtype uint16"):
        odo.track(rgb, depth.astype(np.int16), 0.0)
    with pytest.raises(ValueError, match=r"rgb must have shape \(480, 640, 3\).*got \(480, 640\)"):
        odo.track(rgb[:, :, 0].copy(), depth, 0.0)
    with pytest.raises(ValueError, match=r"got \(480, 640, 4\)"):
        odo.track(np.zeros((480, 640, 4), np.uint8), depth, 0.0)
    with pytest.raises(ValueError, match=r"depth must have shape \(480, 640\)"):
        odo.track(rgb, np.zeros((240, 320), np.uint16), 0.0)
    with pytest.raises(ValueError, match="C-contiguous"):
        odo.track(rgb[:, ::-1], depth, 0.0)
    with pytest.raises(ValueError, match="C-contiguous"):
        odo.track(rgb, np.asfortranarray(depth), 0.0)
    with pytest.raises(ValueError, match="format"):
        odo.track(rgb, depth, 0.0, format="yuv")
    with pytest.raises(TypeError):
        odo.track([[1, 2, 3]], depth, 0.0)
    # Nothing ran, and the object still works.
    assert odo.counters["frames"] == 0
    r = odo.track(rgb, depth, 0.0)
    assert r.state == "not_initialized" and r.pose is None
    assert odo.counters["frames"] == 1


def test_bad_configuration_raises():
    with pytest.raises(ValueError, match="tum9"):
        plumb.Odometry(camera="tum9")
    with pytest.raises(ValueError, match="unknown camera key"):
        plumb.Odometry(camera={"fx": 500, "fy": 500, "cx": 320, "cy": 240, "focal": 3})
    with pytest.raises(ValueError, match="focal length"):
        plumb.Odometry(camera={"fx": 0, "fy": 500, "cx": 320, "cy": 240})
    with pytest.raises(ValueError):
        plumb.Odometry(camera="tum1", line_samples=1)
    with pytest.raises(TypeError):
        plumb.Odometry(camera=5)


def test_staged_runtime_through_the_module():
    seen = []
    result = plumb.run("synth:textured:4:30", mode="fast", on_pose=lambda r: seen.append(r.sequence))
    assert seen == list(range(30))
    assert result["counters"]["frames"] == 30
    assert result["trajectory"]["poses"].shape == (30, 4, 4)

    def boom(_):
        raise KeyError("from the callback")
    with pytest.raises(KeyError, match="from the callback"):
        plumb.run("synth:textured:4:5", on_pose=boom)


def test_evaluate_equals_plumb_eval(plumb_binary, datasets_dir, tmp_path):
    ref = os.path.join(datasets_dir, "reference_trajectories")
    gt_path = os.path.join(ref, "freiburg1_xyz-groundtruth.txt")
    est_path = os.path.join(ref, "freiburg1_xyz-rgbdslam.txt")
    if not os.path.exists(gt_path) or not os.path.exists(est_path):
        pytest.skip("reference trajectories not present")
    cli = json.loads(subprocess.run([plumb_binary, "eval", "--gt", gt_path, "--est", est_path, "--json"],
                                    check=True, stdout=subprocess.PIPE, universal_newlines=True).stdout)
    gt, est = plumb.read_trajectory(gt_path), plumb.read_trajectory(est_path)
    assert gt["poses"].shape[1:] == (4, 4)
    r = plumb.evaluate(gt, est)
    assert r["ate"]["pairs"] == cli["ate"]["pairs"]
    assert r["rpe_translation"]["pairs"] == cli["rpe"]["pairs"]
    for ours, theirs in [(r["ate"]["rmse"], cli["ate"]["rmse_m"]), (r["ate"]["mean"], cli["ate"]["mean_m"]),
                         (r["ate"]["max"], cli["ate"]["max_m"]),
                         (r["rpe_translation"]["rmse"], cli["rpe"]["translation_rmse_m_per_s"]),
                         (r["rpe_rotation"]["rmse"], cli["rpe"]["rotation_rmse_deg_per_s"])]:
        assert "%.6f" % ours == "%.6f" % theirs
    # Round trip through the CLI's writer: same poses, same bytes.
    plumb.write_trajectory(str(tmp_path / "a.txt"), est)
    again = plumb.read_trajectory(str(tmp_path / "a.txt"))
    plumb.write_trajectory(str(tmp_path / "b.txt"), again)
    assert (tmp_path / "a.txt").read_bytes() == (tmp_path / "b.txt").read_bytes()


# head250 from NumPy arrays vs `plumb run`: the module runs the runner's own stages lock-step, so
# the trajectory files must be byte-identical, with the default output delay (60 frames, poses
# refined by local BA) and with delay 0 (poses as tracked). PLUMB_PY_FRAMES sets how many frames
# (default 100, 250 = the whole clip). Loop closing is on in both (the push API runs the loop stage
# lock-step, as `plumb run`'s default mode); PLUMB_PY_FRAMES=250 includes head250's one loop.
@pytest.mark.parametrize("delay", [60, 0])
def test_head250_from_numpy_is_byte_identical_to_plumb_run(plumb_binary, datasets_dir, tmp_path, delay):
    folder = os.path.join(datasets_dir, "tum_fr1_rpy_head250")
    if not os.path.exists(os.path.join(folder, "rgb.txt")):
        pytest.skip("tum_fr1_rpy_head250 not present")
    frames = int(os.environ.get("PLUMB_PY_FRAMES", "100"))
    ref = tmp_path / "plumb_run.txt"
    subprocess.run([plumb_binary, "run", "--dataset", folder, "--max-frames", str(frames), "--out", str(ref),
                    "--output-delay", str(delay)], check=True, stdout=subprocess.DEVNULL)
    reader = plumb.FrameReader(folder)
    odo = plumb.Odometry(camera=reader.camera, output_delay=delay)
    finished, tracked = [], []
    for i, (rgb, depth, t) in enumerate(reader):
        if i == frames:
            break
        r = odo.track(np.ascontiguousarray(rgb), depth, t)
        tracked.append((t, r.pose))
        finished += odo.finished()
    odo.finish()
    finished += odo.finished()
    assert len(finished) == frames
    valid = np.array([T is not None for _, T in finished])
    ours = tmp_path / "python.txt"
    plumb.write_trajectory(str(ours), {
        "timestamps": np.array([t for t, _ in finished]),
        "poses": np.stack([T if T is not None else np.eye(4) for _, T in finished]),
        "valid": valid})
    assert ours.read_bytes() == ref.read_bytes()
    if delay == 0:
        # As tracked: the poses track() returned are the file's poses, exactly.
        for (t, T), (t2, T2) in zip(tracked, finished):
            assert t == t2
            assert (T is None) == (T2 is None)
            if T is not None:
                assert np.array_equal(T, T2)


def test_read_tum_frame_is_the_readers_frame(datasets_dir):
    folder = os.path.join(datasets_dir, "tum_fr1_rpy_head250")
    if not os.path.exists(os.path.join(folder, "rgb.txt")):
        pytest.skip("tum_fr1_rpy_head250 not present")
    reader = plumb.FrameReader(folder)
    frames = [reader.next() for _ in range(3)]
    rgb, depth, t = plumb.read_tum_frame(folder, 2)
    assert t == frames[2][2]
    assert np.array_equal(rgb, frames[2][0]) and np.array_equal(depth, frames[2][1])
    assert not np.array_equal(rgb, frames[1][0])
    bgr, _, _ = reader.next(format="bgr")
    rgb3, _, _ = plumb.read_tum_frame(folder, 3)
    assert np.array_equal(bgr[:, :, ::-1], rgb3)
    assert depth.max() > 0 and rgb.mean() > 10
    with pytest.raises(IndexError):
        plumb.read_tum_frame(folder, 250)
