"""`wheelins live --ros` (docs/live.md) on a real ROS 1 master: a simulated dataset written as
a bag (scripts/stream-lines.py --bag), played with `rosbag play` into the node, its /odom,
/tf and /diagnostics recorded with `rosbag record` and compared with `wheelins run` on the
same files. Skipped where Debian's ROS 1 (roscore, python3-rosbag) or a program built with
the ROS node (WHEELINS_ROS1) is not there. Run by CTest (python_tests)."""

import csv
import math
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import time

import numpy as np
import pytest

rosbag = pytest.importorskip("rosbag")
rosgraph = pytest.importorskip("rosgraph")

WHEELINS = os.environ.get("WHEELINS_BINARY", "wheelins")
SOURCE = os.environ.get("WHEELINS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SOURCE, "scripts", "stream-lines.py")
MODULES = "left-C1,right-C1,body-C1"
SPEED = "2"  # rosbag play -r: 40 s of data in 20 s
# The reorder window [s of data] of these tests: a topic's messages may lag the others' by a
# second of wall time on a loaded machine (CI runs two tests at once), and a message later
# than the window is dropped (counted), which would change the trajectory.
WINDOW = "2"


def _has_ros_node():
    try:
        p = subprocess.run([WHEELINS, "live", "--help"], capture_output=True, text=True, timeout=30)
    except OSError:
        return False
    return "--ros" in p.stdout


pytestmark = pytest.mark.skipif(shutil.which("roscore") is None or shutil.which("rosbag") is None
                                or not _has_ros_node(),
                                reason="needs roscore, rosbag and wheelins built with the ROS node")


def run(args, **kw):
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True, **kw)
    assert p.returncode == 0, f"{' '.join(map(str, args))}: {p.returncode}\n{p.stderr}"
    return p


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    """A roscore of its own on a free port; the environment that points at it."""
    home = tmp_path_factory.mktemp("ros")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_HOME=str(home),
               ROS_LOG_DIR=str(home / "log"), PYTHONPATH=os.environ.get("PYTHONPATH", ""))
    core = subprocess.Popen(["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    master = rosgraph.Master("/wheelins_test", master_uri=env["ROS_MASTER_URI"])
    for _ in range(150):
        if master.is_online():
            break
        time.sleep(0.1)
    else:
        os.killpg(core.pid, signal.SIGKILL)
        pytest.fail("roscore did not come up")
    yield env
    os.killpg(core.pid, signal.SIGINT)
    try:
        core.wait(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(core.pid, signal.SIGKILL)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """40 s simulated (10 s standing), its bag, and `wheelins run`'s trajectory of it at every
    epoch (the node publishes on a grid of its own: every 0.1 s of data from its first state)."""
    d = tmp_path_factory.mktemp("live")
    run([WHEELINS, "simulate", "--duration", "40", "--static", "10", "--chips", "1", "--no-ideal", "-q",
         "--out", d / "data"])
    manifest = d / "data" / "manifest.yaml"
    run([WHEELINS, "run", "-m", manifest, "--modules", MODULES, "--calibration", "manifest",
         "--no-data-checks", "--no-evaluate", "--full-rate", "-q", "-o", d / "files"])
    with open(d / "files" / "trajectory.csv") as f:
        rows = {round(float(r["t_s"]), 6): r for r in csv.DictReader(f)}
    return d, manifest, rows


def navigate(env, dirpath, manifest, bags, meanwhile=None, publisher=None, kill_after=None, play_args=()):
    """The node on `bags` played by rosbag play (with `play_args`; the command `meanwhile` run
    from 2 s into the play to its end; the command `publisher`, a publisher of its own, started
    before the play and killed `kill_after` s into it); (the node's exit, its stderr, the
    recorded messages)."""
    rec_bag = dirpath / "recorded.bag"
    node = subprocess.Popen([WHEELINS, "live", "--ros", "-m", str(manifest), "--modules", MODULES,
                             "--calibration", "manifest", "--window", WINDOW, "--idle-exit", "3",
                             "-o", str(dirpath / "live"), "__name:=wheelins_node"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    rec = subprocess.Popen(["rosbag", "record", "-O", str(rec_bag), "/odom", "/tf", "/diagnostics",
                            "__name:=recorder"], env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        # --wait-for-subscribers: every topic has the node as a subscriber before the first message.
        time.sleep(1.0)
        assert node.poll() is None, node.communicate()[1]
        pub = subprocess.Popen(publisher, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True) if publisher else None
        # --queue: rosbag play's outgoing queue (100 by default) would drop messages while the
        # node is starved of CPU.
        play = subprocess.Popen(["rosbag", "play", "-q", "-r", SPEED, "--queue", "100000", "--wait-for-subscribers",
                                 *map(str, bags), *play_args],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        other = None
        started = time.monotonic()
        if meanwhile:
            time.sleep(2.0)
            other = subprocess.Popen(meanwhile, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     start_new_session=True)
        try:
            if pub:
                time.sleep(max(0.0, started + kill_after - time.monotonic()))
                assert pub.poll() is None, pub.communicate()[1]
                os.killpg(pub.pid, signal.SIGKILL)  # the process dies: no goodbye on its topic
                pub.wait(timeout=30)
            assert play.wait(timeout=90) == 0, play.stderr.read()
        finally:
            if other:
                os.killpg(other.pid, signal.SIGINT)
                other.wait(timeout=30)
            if pub and pub.poll() is None:
                os.killpg(pub.pid, signal.SIGKILL)
                pub.wait(timeout=30)
        _, err = node.communicate(timeout=60)
    finally:
        if node.poll() is None:
            node.kill()
        time.sleep(1.0)  # the recorder writes what it received
        os.killpg(rec.pid, signal.SIGINT)
        rec.wait(timeout=30)
        # rosbag's recorder (a child of the rosbag command) closes the bag after its parent ended.
        for _ in range(200):
            if rec_bag.exists() and not (dirpath / "recorded.bag.active").exists():
                break
            time.sleep(0.1)
    msgs = {"/odom": [], "/tf": [], "/diagnostics": []}
    with rosbag.Bag(str(rec_bag)) as b:
        for topic, m, _ in b.read_messages():
            msgs[topic].append(m)
    return node.returncode, err, msgs


def frd_to_enu(row):
    """A trajectory.csv row's NED position and roll/pitch/heading as ENU and body FLU -> ENU."""
    p = np.array([float(row["east_m"]), float(row["north_m"]), -float(row["down_m"])])
    r, pt, y = (math.radians(float(row[k])) for k in ("roll_deg", "pitch_deg", "heading_deg"))
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(pt), math.sin(pt), math.cos(y), math.sin(y)
    c_nb = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) \
        @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    swap = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
    return p, swap @ c_nb @ np.diag([1.0, -1.0, -1.0])


def quat_matrix(q):
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def compare(odom, rows, until):
    """Largest position [m] and rotation [deg] difference of the odometry against the file run's
    records at the same times (in the odom frame: the first state's pose), up to `until`."""
    first = rows[round(odom[0].header.stamp.to_sec(), 6)]
    p0, c0 = frd_to_enu(first)
    psi = math.atan2(c0[1, 0], c0[0, 0])
    rz = np.array([[math.cos(psi), math.sin(psi), 0], [-math.sin(psi), math.cos(psi), 0], [0, 0, 1]])
    dp = da = 0.0
    n = 0
    for m in odom:
        t = m.header.stamp.to_sec()
        if t > until:
            break
        row = rows[round(t, 6)]
        p, c = frd_to_enu(row)
        pos = m.pose.pose.position
        dp = max(dp, float(np.linalg.norm(rz @ (p - p0) - np.array([pos.x, pos.y, pos.z]))))
        d = (rz @ c).T @ quat_matrix(m.pose.pose.orientation)
        da = max(da, math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(d) - 1) / 2)))))
        # The covariance: the run's sigmas (the horizontal ones turned: their sum stays).
        cov = m.pose.covariance
        horiz = float(row["north_std_m"]) ** 2 + float(row["east_std_m"]) ** 2
        assert cov[0] + cov[7] == pytest.approx(horiz, rel=1e-6, abs=1e-12)
        assert cov[14] == pytest.approx(float(row["down_std_m"]) ** 2, rel=1e-6, abs=1e-12)
        assert cov[35] == pytest.approx(math.radians(float(row["heading_std_deg"])) ** 2, rel=1e-5, abs=1e-15)
        n += 1
    return dp, da, n


def test_the_node_publishes_the_file_runs_trajectory(ros, dataset, tmp_path):
    d, manifest, rows = dataset
    bag = tmp_path / "in.bag"
    run([sys.executable, SCRIPT, manifest, MODULES, "--bag", bag])
    code, err, msgs = navigate(ros, tmp_path, manifest, [bag])
    assert code == 0, err
    assert "left out: 0 unreadable or not navigated, 0 late, 0 refused" in err, err
    odom = msgs["/odom"]
    assert len(odom) >= 290, err  # a state every 0.1 s of the 30 s navigated
    assert all(m.header.frame_id == "odom" and m.child_frame_id == "base_link" for m in odom)
    p = odom[0].pose.pose
    first = quat_matrix(p.orientation)  # base_link's x along odom's x at the first state
    assert abs(p.position.x) < 1e-12 and abs(p.position.y) < 1e-12 and abs(first[1, 0]) < 1e-12
    # rosbag play may end before its last messages left it: the states of the last second of
    # data are not compared (the samples differ there); all others used the same samples.
    last = max(rows) - 1.0
    dp, da, n = compare(odom, rows, last)
    assert n >= 280
    assert dp < 1e-3 and da < 0.01, (dp, da)
    tf = [t for m in msgs["/tf"] for t in m.transforms]
    assert len(tf) == len(odom)
    assert all(t.header.frame_id == "odom" and t.child_frame_id == "base_link" for t in tf)
    assert tf[-1].transform.translation.x == odom[-1].pose.pose.position.x
    names = {s.name for m in msgs["/diagnostics"] for s in m.status}
    assert {"wheelins: left-C1", "wheelins: right-C1", "wheelins: body-C1", "wheelins: navigation"} <= names


def write_bad_bag(path, t0, sample):
    """Bad input on the left wheel's topic at t0 + ...: a NaN, a wrong frame id, a time 5 s back (past the window),
    and a burst of three duplicates of `sample` (a record of its file: t, gyro, accel)."""
    import rospy
    from sensor_msgs.msg import Imu

    def imu(t, frame="left-C1", gx=0.0):
        m = Imu()
        m.header.stamp = rospy.Time.from_sec(t)
        m.header.frame_id = frame
        m.angular_velocity.x = gx
        m.linear_acceleration.z = 9.8
        return m

    with rosbag.Bag(str(path), "w") as b:
        b.write("/left_C1/imu", imu(t0 + 0.0025, gx=float("nan")), rospy.Time.from_sec(t0 + 1.0025))
        b.write("/left_C1/imu", imu(t0 + 0.0075, frame="camera"), rospy.Time.from_sec(t0 + 1.0075))
        b.write("/left_C1/imu", imu(t0 - 5.0), rospy.Time.from_sec(t0 + 1.0125))
        dup = imu(sample[0])
        dup.angular_velocity.x, dup.angular_velocity.y, dup.angular_velocity.z = sample[1:4]
        dup.linear_acceleration.x, dup.linear_acceleration.y, dup.linear_acceleration.z = sample[4:7]
        for k in range(3):
            b.write("/left_C1/imu", dup, rospy.Time.from_sec(sample[0] + 1.0 + 1e-4 * (k + 1)))


# A publisher of the body IMU's topic in a process of its own (killed mid-run by the test): it
# relays the bag's messages, played under another name, once the node is connected to it.
RELAY = """
import sys
import rospy
from sensor_msgs.msg import Imu
rospy.init_node("body_imu_publisher")
pub = rospy.Publisher(sys.argv[2], Imu, queue_size=100000, tcp_nodelay=True)
while pub.get_num_connections() < 1 and not rospy.is_shutdown():
    rospy.sleep(0.02)
rospy.Subscriber(sys.argv[1], Imu, pub.publish, queue_size=100000, tcp_nodelay=True)
rospy.spin()
"""


def test_a_killed_publisher_and_bad_messages_get_diagnostics_and_the_odometry_goes_on(ros, dataset, tmp_path):
    d, manifest, rows = dataset
    bag = tmp_path / "in.bag"
    run([sys.executable, SCRIPT, manifest, MODULES, "--bag", bag])
    bad = tmp_path / "bad.bag"
    with open(manifest.parent / "left-wheel-imu" / "tri_C1_imu.bin", "rb") as f:
        data = f.read()
    sample = struct.unpack_from("<7d", data, 56 * 4400)  # t = 100022.005
    write_bad_bag(bad, 100020.0, sample)
    # And a publisher of another type on the body's topic (the master then lists it as such).
    # The body IMU's publisher is killed about 15 s of data into the navigation (rosbag play at
    # SPEED from t = 100000).
    kill_after = 25.0 / float(SPEED)
    code, err, msgs = navigate(ros, tmp_path, manifest, [bag, bad],
                               ["rostopic", "pub", "-r", "5", "/body_C1/imu", "std_msgs/String", "data: not an IMU"],
                               publisher=[sys.executable, "-c", RELAY, "/body_C1/imu_bag", "/body_C1/imu"],
                               kill_after=kill_after, play_args=["/body_C1/imu:=/body_C1/imu_bag"])
    assert code == 3, err  # input was left out, and said so
    assert "left_C1/imu seq 0: angular_velocity.x is NaN" in err, err
    assert "frame_id 'camera' is not the topic's first one, 'left-C1'" in err, err
    assert "arrived after the reorder window" in err, err
    assert "repeats the previous sample's time" in err, err
    odom = msgs["/odom"]
    assert len(odom) >= 290, err
    statuses = [s for m in msgs["/diagnostics"] for s in m.status if s.name == "wheelins: body-C1"]
    # The last body message the node received (the diagnostics' value): the publisher died
    # mid-run, and the odometry went on to the end of the data.
    stop = float(dict((v.key, v.value) for v in statuses[-1].values)["last stamp [s]"])
    assert 100015.0 < stop < 100035.0, stop
    assert odom[-1].header.stamp.to_sec() > max(stop + 4.0, 100038.0)
    assert all(math.isfinite(m.pose.pose.position.x) for m in odom)
    # Until the body's topic stopped, the bad messages changed nothing.
    dp, da, n = compare(odom, rows, stop - 0.5)
    assert n >= 50 and dp < 1e-3 and da < 0.01, (dp, da, n)
    assert any(s.level == 2 and "no message on body_C1/imu" in s.message for s in statuses), \
        [s.message for s in statuses]
    assert any(s.level == 2 and "of type std_msgs/String" in s.message for s in statuses), [s.message for s in statuses]
    nav = [s for m in msgs["/diagnostics"] for s in m.status if s.name == "wheelins: navigation"]
    assert nav[-1].level == 1  # input was left out


def test_the_launch_file_starts_the_program_with_the_manifest(ros, dataset):
    _, manifest, _ = dataset
    env = dict(ros, ROS_PACKAGE_PATH=os.path.join(os.path.dirname(os.path.abspath(WHEELINS)), "ros"))
    out = run(["roslaunch", "--args", "wheelins", "wheelins", "live.launch", f"manifest:={manifest}"], env=env).stdout
    assert out.split()[:5] == [os.path.realpath(WHEELINS), "live", "--ros", "-m", str(manifest)] or \
        out.split()[1:5] == ["live", "--ros", "-m", str(manifest)], out
