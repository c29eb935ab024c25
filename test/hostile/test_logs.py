"""Logs and newcomer friction under faults: a recorder killed with SIGKILL leaves a file that
``rosbags`` and ``mcap``'s reader refuse; ``att-log repair`` (and the recorder's next start on the
same path) makes it whole for both, every message decoded, at most a flush interval lost.
``att-demo``'s domain: the user's ROS_DOMAIN_ID is honoured, a malformed one refused in one line."""
from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from att_msgs_py.log import read_log
from att_planner.tools.launch import Suite, isolated_env

ATT_LOG = Path(sys.executable).parent / "att-log"
KILL_AFTER = 4.0          # s of recording before the SIGKILL
FLUSH_PERIOD = 0.5        # the recorder's default


def rosbags_messages(path: Path) -> dict[str, list]:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        for connection, _, raw in reader.messages():
            out.setdefault(connection.topic, []).append(reader.deserialize(raw, connection.msgtype))
    return out


def mcap_messages(path: Path, decoded: bool) -> list:
    with open(path, "rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        return list(reader.iter_decoded_messages() if decoded else reader.iter_messages())


def record_and_kill(suite: Suite, path: Path) -> float:
    """Recorder + simulator (no lockstep, RTF 2); SIGKILL the recorder after KILL_AFTER s of states."""
    suite.start("recorder", {"output": str(path)})
    suite.start("simulator", {"scenario": "swift_demo", "lockstep": False, "real_time_factor": 2.0,
                              "wait_for_subscribers": 1})
    assert suite.wait_for_output("recorder", "recording", 30), suite.log_text("recorder")
    deadline = time.monotonic() + 30
    while not (path.is_file() and path.stat().st_size > 1000) and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(KILL_AFTER)
    suite.procs["recorder"].send_signal(signal.SIGKILL)
    killed_at = time.time()
    assert suite.procs["recorder"].wait(10) == -signal.SIGKILL
    return killed_at


@pytest.mark.ros
def test_a_killed_recorders_log_is_refused_raw_and_decoded_whole_once_repaired(tmp_path):
    from rosbags.highlevel import AnyReaderError

    assert ATT_LOG.is_file(), "att-log is not installed: run make setup"
    suite = Suite(isolated_env(), tmp_path)
    killed = tmp_path / "killed.mcap"
    try:
        killed_at = record_and_kill(suite, killed)
        # the bug: neither independent reader opens the raw file
        with pytest.raises(AnyReaderError, match="magic"):
            rosbags_messages(killed)
        for decoded in (False, True):
            with pytest.raises(McapError):
                mcap_messages(killed, decoded)
        salvaged = read_log(killed)
        counts = {t: len(v) for t, v in salvaged.items()}
        assert counts["/spacecraft/state"] > 2 * KILL_AFTER * 20 * 0.5, counts   # 40 states/s of wall time
        info = subprocess.run([str(ATT_LOG), "info", str(killed)], capture_output=True, text=True, timeout=60)
        assert info.returncode == 1 and "INCOMPLETE" in info.stdout, info.stdout + info.stderr
        done = subprocess.run([str(ATT_LOG), "repair", str(killed)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        repaired = tmp_path / "killed.repaired.mcap"
        assert f"wrote {repaired}: complete and indexed" in done.stdout, done.stdout
        # both readers open the repaired file and decode every message read_log recovered
        by_rosbags = rosbags_messages(repaired)
        assert {t: len(v) for t, v in by_rosbags.items()} == counts
        decoded = mcap_messages(repaired, decoded=True)
        assert len(decoded) == sum(counts.values())
        assert [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in by_rosbags["/spacecraft/state"]] == \
            pytest.approx(list(salvaged["/spacecraft/state"]["header.stamp"]), abs=1e-9)
        last = max(message.log_time for _, _, message, _ in decoded) * 1e-9
        assert killed_at - last < 2 * FLUSH_PERIOD, f"{killed_at - last:.2f} s lost (flush every {FLUSH_PERIOD} s)"
        # the recorder started again on the same path repairs the leftover aside before recording
        repaired_bytes = repaired.read_bytes()
        repaired.unlink()
        suite.start("recorder", {"output": str(killed)})
        assert suite.wait_for_output("recorder", "repaired into", 30), suite.log_text("recorder")
        assert repaired.read_bytes() == repaired_bytes
    finally:
        suite.stop()


# -- att-demo's domain ---------------------------------------------------------------------------

def test_a_domain_the_user_set_is_kept_and_localhost_stays_the_default():
    from att_planner.tools.demo import domain_line

    env = isolated_env(inherit=True, base={"ROS_DOMAIN_ID": "42"})
    assert env["ROS_DOMAIN_ID"] == "42" and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert "ROS_DOMAIN_ID 42 (inherited from your environment)" in domain_line(env, {"ROS_DOMAIN_ID": "42"})
    env = isolated_env(inherit=True, base={"ROS_DOMAIN_ID": " 7 ", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"})
    assert (env["ROS_DOMAIN_ID"], env["ROS_AUTOMATIC_DISCOVERY_RANGE"]) == ("7", "SUBNET")
    for base in ({}, {"ROS_DOMAIN_ID": ""}, {"ROS_DOMAIN_ID": "  "}):
        env = isolated_env(inherit=True, base=base)
        assert 1 <= int(env["ROS_DOMAIN_ID"]) <= 200 and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
        assert "chosen at random: ROS_DOMAIN_ID is unset" in domain_line(env, base)
    # tests (inherit=False) always get a random domain, whatever the environment says
    domains = {isolated_env(base={"ROS_DOMAIN_ID": "42"})["ROS_DOMAIN_ID"] for _ in range(20)}
    assert domains != {"42"} and all(1 <= int(d) <= 200 for d in domains)
    assert isolated_env(5, base={"ROS_DOMAIN_ID": "42"}, inherit=True)["ROS_DOMAIN_ID"] == "5"


MALFORMED = [("abc", ""), ("-1", ""), ("233", ""), ("1e3", ""), ("4\x01", ""), ("9" * 50, ""), ("\u00b2", ""),
             ("\u0663", ""), ("3", "EVERYWHERE"), ("3", "localhost;rm")]


@pytest.mark.parametrize("domain, discovery", MALFORMED)
def test_att_demo_refuses_a_malformed_domain_in_one_line(tmp_path, monkeypatch, capsys, domain, discovery):
    from att_planner.tools import demo

    monkeypatch.setenv("ROS_DOMAIN_ID", domain)
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", discovery)
    assert demo.main(["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    name = "ROS_DOMAIN_ID" if not discovery else "ROS_AUTOMATIC_DISCOVERY_RANGE"
    assert err.count("\n") == 1 and err.startswith(f"att-demo: {name} is '") and "expected" in err, err
    assert list(tmp_path.iterdir()) == []                 # nothing started, nothing written


@pytest.mark.parametrize("scenario, words", [("bruni_celani", "demo"), ("no_such_scenario", "unknown")])
def test_att_demo_refuses_a_scenario_it_cannot_run_in_one_line(tmp_path, capsys, scenario, words):
    from att_planner.tools import demo

    assert demo.main(["--scenario", scenario, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("att-demo: ") and words in err, err
    assert list(tmp_path.iterdir()) == []                 # nothing started, nothing written
