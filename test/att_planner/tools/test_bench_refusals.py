"""The studies that start nodes (``att-bench day``, ``att-bench soak``) refuse what they cannot fly
in one sentence naming the argument or variable, before any node starts or any file is written; so
does ``att-bench rtf``, which flies in process, before any flight."""
import pytest

from att_planner.tools.bench import main


@pytest.mark.parametrize("argv, env, says", [
    (["day", "--mission", "no_such_mission"], {}, "att-bench day: unknown mission 'no_such_mission'"),
    (["day"], {"ROS_DOMAIN_ID": "abc"}, "att-bench day: ROS_DOMAIN_ID is 'abc': expected"),
    (["day"], {"ROS_DOMAIN_ID": "233"}, "att-bench day: ROS_DOMAIN_ID is '233': expected"),
    (["day"], {"ROS_AUTOMATIC_DISCOVERY_RANGE": "EVERYWHERE"},
     "att-bench day: ROS_AUTOMATIC_DISCOVERY_RANGE is 'EVERYWHERE': expected"),
    (["soak", "--scenario", "no_such_scenario"], {}, "att-bench soak: unknown spacecraft/scenario 'no_such_scenario'"),
    (["soak", "--scenario", "broken.yaml"], {}, "att-bench soak: broken.yaml:2: (file): expected valid YAML"),
    (["day", "--mission", "broken.yaml"], {}, "att-bench day: broken.yaml:2: (file): expected valid YAML"),
    (["soak", "--orbits", "-1"], {}, "att-bench soak: --orbits must be a finite number > 0, found -1"),
    (["soak", "--hours", "nan"], {}, "att-bench soak: --hours must be a finite number > 0, found nan"),
    (["soak", "--rate-Hz", "0"], {}, "att-bench soak: --rate-Hz must be a finite number > 0, found 0"),
])
def test_a_study_that_starts_nodes_refuses_in_one_sentence(tmp_path, monkeypatch, argv, env, says):
    (tmp_path / "broken.yaml").write_text("spacecraft: [\n")
    argv = [str(tmp_path / a) if a == "broken.yaml" else a for a in argv]
    says = says.replace("broken.yaml", str(tmp_path / "broken.yaml"))
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    monkeypatch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", str(out)])
    message = str(exc.value.code)
    assert message.startswith(says) and "\n" not in message, message
    assert not out.exists()                               # nothing started, nothing written


@pytest.mark.parametrize("text, says", [
    ("spacecraft: [\n", "scenario.yaml:2: (file): expected valid YAML"),
    ("spacecraft: aeos\nno_such_key: 1\n", "scenario.yaml:2: no_such_key: expected one of the keys"),
])
def test_rtf_blames_a_scenario_file_that_does_not_read_not_the_plan(tmp_path, text, says):
    path = tmp_path / "scenario.yaml"
    path.write_text(text)
    out = tmp_path / "rtf.json"
    with pytest.raises(SystemExit) as exc:
        main(["rtf", "--in-process", "--scenario", str(path), "--no-profile", "--json", str(out)])
    message = str(exc.value.code)
    assert message.startswith(f"att-bench rtf: {tmp_path / says}") and "\n" not in message, message
    assert "planned" not in message, message
    assert not out.exists()                               # nothing flown, nothing written
