# SPDX-License-Identifier: Apache-2.0
"""bench.json records the engine's speed figures that `make bench` wrote to OUT/speed.json
(icoac_bench --json), and goes without them when that file is absent or damaged."""
import json
import subprocess
from pathlib import Path

from icoac.studies.bench import SPEED_FILE, BenchLog

ROOT = Path(__file__).resolve().parents[2]


def test_bench_json_carries_the_speed_figures(tmp_path):
    figures = {"lanes": [{"plant": "cart_pole", "mode": "ico", "lanes": 16, "ns_per_tick": 30.0, "ticks": 5}]}
    (tmp_path / SPEED_FILE).write_text(json.dumps(figures))
    log = BenchLog(tmp_path, {"profile": "quick"})
    log.stage("grid", 1.0)
    assert json.loads((tmp_path / "bench.json").read_text())["speed"] == figures


def test_bench_json_without_speed_figures(tmp_path):
    (tmp_path / "a").mkdir()
    BenchLog(tmp_path / "a", {}).flush()
    assert "speed" not in json.loads((tmp_path / "a" / "bench.json").read_text())
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / SPEED_FILE).write_text("{not json")
    BenchLog(tmp_path / "b", {}).flush()
    assert "speed" not in json.loads((tmp_path / "b" / "bench.json").read_text())


def test_icoac_bench_json_has_every_plant_mode_and_block(tmp_path):
    """icoac_bench --quick --json: a figure for each plant, mode and block size of 1, 2, 8, 16, 64."""
    from icoac.core import binding as B
    from icoac.core.plants import PLANTS

    exe = B.LIBRARY_PATH.parent / "icoac_bench"
    out = tmp_path / SPEED_FILE
    subprocess.run([str(exe), "--quick", "--json", str(out)], check=True, capture_output=True, timeout=300)
    data = json.loads(out.read_text())
    got = {(r["plant"], r["mode"], r["lanes"]) for r in data["lanes"]}
    assert got == {(p, m, n) for p in PLANTS for m in ("ico", "rl", "search") for n in (1, 2, 8, 16, 64)}
    assert all(r["ns_per_tick"] > 0 and r["ticks"] > 0 for r in data["lanes"])
    assert [r["mode"] for r in data["balanced"]] == ["ico", "rl"] and data["grid"]["ticks"] > 0
