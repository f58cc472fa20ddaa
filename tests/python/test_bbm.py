"""The Python module against the program: same model, same state (hash); the
numpy arrays' shapes, units and write protection; errors that name the key.

Run by CTest (python.pytest) with PYTHONPATH=build/python, BBM_EXE (the bbm
program) and BBM_SOURCE_DIR set."""

import json
import math
import os
import pathlib
import subprocess
import sys
import tomllib

import numpy as np

import pytest

import bbm

SOURCE = pathlib.Path(os.environ.get("BBM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BBM_EXE = os.environ.get("BBM_EXE", str(SOURCE / "build/apps/bbm"))
INSITU = SOURCE / "examples/verification/insitu_voronoi.toml"
HYBRID = SOURCE / "examples/verification/hybrid_elastic.toml"
TUNNEL = SOURCE / "examples/tunnel_voronoi.toml"


def cli(*args, cwd=None):
    done = subprocess.run([BBM_EXE, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    return done.returncode, done.stdout + done.stderr


def cli_run(model, out):
    rc, log = cli("run", model, "--out", out, "--quiet")
    assert rc == 0, log
    return json.loads((pathlib.Path(out) / "summary.json").read_text())


def short_tunnel(seed=7):
    """The paper's tunnel with a short failure stage (a test, not a study)."""
    d = tomllib.loads(TUNNEL.read_text())
    for region in d["region"]:
        if region["name"] == "bonded":
            region["pattern"]["seed"] = seed
    for stage in d["stage"]:
        if stage["name"] == "excavation":
            stage["relax_steps"] = 300
        if stage["name"] == "failure":
            stage["max_steps"] = 300
    return d


def test_model_run_matches_the_program(tmp_path):
    m = bbm.Model(str(INSITU))
    m.run()
    s = m.summary()
    ref = cli_run(INSITU, tmp_path / "cli")
    assert s["state_hash"] == ref["state_hash"]
    # Which bbm made it: the version and commit, as `bbm --version` prints them.
    assert s["bbm_version"] == ref["bbm_version"]
    assert cli("--version")[1].strip() == "bbm " + ref["bbm_version"]
    assert s["steps"] == ref["steps"] == 100
    assert s["complete"] and ref["complete"]
    assert [x["name"] for x in s["stages"]] == [x["name"] for x in ref["stages"]]
    assert m.stages_done == m.stage_names


def test_tunnel_from_dict_same_as_program(tmp_path):
    d = short_tunnel()
    path = tmp_path / "tunnel.toml"
    path.write_text(bbm.to_toml(d))
    ref = cli_run(path, tmp_path / "cli")
    m = bbm.Model.from_dict(d, threads=2)
    m.run()
    s = m.summary()
    assert s["state_hash"] == ref["state_hash"]
    assert s["opening"]["cracks_springline_sector"] == ref["opening"]["cracks_springline_sector"]
    # The dict read back from the file is the file: the same model.
    assert bbm.Model(str(path)).summary()["blocks"] == s["blocks"]


def test_block_views_shapes_units_and_protection():
    m = bbm.Model(str(INSITU))
    b = m.blocks
    n = b.count
    assert n > 50
    assert b.centroid.shape == (n, 2) and b.centroid.dtype == np.float64
    assert b.velocity.shape == (n, 2) and b.rotation.shape == (n,)
    assert b.region.shape == (n,) and b.region.dtype == np.int32
    # Areas in m² tile the 4 m x 4 m region.
    assert b.area.sum() == pytest.approx(16.0, rel=1e-9)
    # Views of the solver's memory: no copy, and not writable.
    assert not b.centroid.flags.writeable and not b.centroid.flags.owndata
    with pytest.raises(ValueError):
        b.centroid[0, 0] = 1.0
    before = b.centroid.copy()
    m.run_stage("insitu")
    # Block stresses in Pa, tension positive: the in-situ state sxx = -10, syy = -20 MPa.
    s = b.stress
    assert s.shape == (n, 3)
    inner = (np.abs(b.centroid - 2.0) < 1.2).all(axis=1)
    assert np.median(s[inner, 0]) == pytest.approx(-10e6, rel=0.02)
    assert np.median(s[inner, 1]) == pytest.approx(-20e6, rel=0.02)
    m.run()
    # Equilibrium: nothing moved (displacement in m, computed from the centroids).
    assert np.abs(b.displacement).max() < 1e-6
    assert np.abs(b.centroid - before).max() < 1e-6


def test_contact_arrays():
    m = bbm.Model(str(INSITU))
    m.run_stage("insitu")
    c = m.contacts
    k = c.count
    assert k > 100
    assert c.normal_stress.shape == (k,) and c.shear_stress.shape == (k,)
    assert c.block_pair.shape == (k, 2) and c.block_pair.dtype == np.int32
    assert c.block_pair.max() < m.blocks.count
    assert c.state.shape == (k,) and set(np.unique(c.state)) <= {0, 1, 2, 3, 4}
    assert np.allclose(np.linalg.norm(c.normal, axis=1), 1.0)
    # sigma_n = n . sigma . n of the in-situ field (sxx -10, syy -20, sxy -3 MPa),
    # compression positive, Pa.
    n = c.normal
    expected = -(n[:, 0] ** 2 * -10e6 + n[:, 1] ** 2 * -20e6 + 2 * n[:, 0] * n[:, 1] * -3e6)
    assert np.allclose(c.normal_stress, expected, rtol=1e-6, atol=1.0)
    assert (c.damage == 0).all() and c.bonded.all()


def test_zone_views_of_deformable_blocks():
    m = bbm.Model(str(HYBRID))
    z = m.zones
    assert z.count > 0
    assert z.nodes.shape == (z.count, 3) and z.stress.shape == (z.count, 3)
    assert z.nodes.max() < m.nodes.count
    assert (z.area > 0).all()
    assert not z.stress.flags.writeable
    m.run()
    assert np.isfinite(z.stress).all() and np.abs(z.stress).max() > 0
    # The view follows the state: it is the solver's memory.
    assert z.stress.ctypes.data == m.zones.stress.ctypes.data
    assert m.nodes.position.shape == (m.nodes.count, 2)


def test_step_callback_checkpoint_and_resume(tmp_path):
    ref = bbm.Model(str(INSITU))
    ref.run()
    seen = []
    m = bbm.Model(str(INSITU))
    m.run(callback=lambda model: seen.append(model.steps) or model.steps < 40, every=20)
    assert m.steps == 40 and seen == [0, 20, 40]  # the in-situ stage's end, then every 20
    m.checkpoint(tmp_path / "half.bin")
    resumed = bbm.Model.resume(str(tmp_path / "half.bin"))
    assert resumed.steps == 40
    resumed.run()
    assert resumed.steps == 100
    assert resumed.summary()["state_hash"] == ref.summary()["state_hash"]
    m.step(5)
    assert m.steps == 45


def test_trigon_tunnel_checkpoint_mid_excavation_resumes_exactly(tmp_path):
    """Issue 27: stopped while contacts are born and renumbered, the trigon
    tunnel resumed through Model.resume (on another thread count) ends in the
    state of the uninterrupted run (its failure stage cut to 6,000 steps)."""
    d = tomllib.loads((SOURCE / "examples/tunnel_trigon.toml").read_text())
    for stage in d["stage"]:
        if stage["name"] == "failure":
            stage["max_steps"] = 6000
    ref = bbm.Model.from_dict(d)
    ref.run()
    m = bbm.Model.from_dict(d)
    m.run(callback=lambda model: model.steps < 1901, every=1)
    assert m.steps == 1901
    m.checkpoint(tmp_path / "trigon.bin")
    resumed = bbm.Model.resume(str(tmp_path / "trigon.bin"), threads=2)
    resumed.run()
    s, r = resumed.summary(), ref.summary()
    assert s["steps"] == r["steps"] == 9000
    assert s["cracks"] == r["cracks"]
    assert s["state_hash"] == r["state_hash"]
    # The verdict of the resumed run is the uninterrupted one's (issue 24): the
    # trigon tunnel cut at 6,000 failure steps is still breaking.
    assert s["verdict"] == r["verdict"]
    assert s["verdict"]["kind"] == "failing"
    assert s["verdict"]["cracks_in_window"] > 0


def test_checkpoint_of_an_older_format_is_refused(tmp_path):
    old = tmp_path / "old.bin"
    old.write_bytes(b"bbm-model-checkpoint-1" + bytes(64))
    with pytest.raises(bbm.InputError, match="format 1"):
        bbm.Model.resume(str(old))


def test_state_fields_are_the_solvers_list():
    """Model.state_fields() is the list the checkpoint, hash and memory report walk."""
    m = bbm.Model(str(HYBRID))
    m.step(10)
    fields = {f["name"]: f for f in m.state_fields()}
    assert fields["blocks.centroid"]["saved"] and fields["blocks.centroid"]["hashed"]
    assert fields["contacts.history"]["hashed"] and not fields["contacts.normal"]["saved"]
    assert fields["monitor.samples"]["saved"] and not fields["monitor.samples"]["hashed"]
    assert fields["blocks.local"]["model"]
    np.testing.assert_array_equal(m.state("blocks.centroid"), m.blocks.centroid)
    np.testing.assert_array_equal(m.state("nodes.velocity"), m.nodes.velocity)
    assert m.state("contacts.history").shape == (m.contacts.count, 64)  # a record: its bytes
    assert m.state("solver.steps").tolist() == [10]
    with pytest.raises(KeyError, match="state_fields"):
        m.state("blocks.nothing")


def test_bolt_arrays_of_the_bolted_tunnel():
    m = bbm.Model(str(SOURCE / "examples/support/tunnel_voronoi_bolted.toml"), threads=2)
    assert m.bolts.count == 0  # installed by a stage
    m.run()
    b = m.bolts
    assert b.set_names == ["rebar"]
    assert b.position.shape == (b.count, 2)
    segments = len(b.segment_node)
    drawn = b.lines  # per bolt, as bolts.pvd has them
    assert drawn["axial_force_kN"].shape == (segments,) and b.state.shape == (segments,)
    # Loaded in tension by the converging wall, within the steel's yield (200 kN).
    assert 10 < drawn["axial_force_kN"].max() <= 200 * (1 + 1e-9)
    assert np.abs(b.bond).max() > 0
    assert b.summary[0]["name"] == "rebar" and b.summary[0]["yielded"] >= 0
    # Every support type's fields are there, dowels too (none in this model).
    assert m.dowels.count == 0 and "shear" in m.dowels.fields


def test_liner_arrays_of_the_shotcreted_tunnel():
    m = bbm.Model(str(SOURCE / "examples/support/tunnel_voronoi_bolted_shotcrete.toml"), threads=2)
    m.run()
    l = m.liners
    assert l.set_names == ["shotcrete"]
    elements = len(l.element_node)
    assert l.position.shape == (l.count, 2) and l.moment_a.shape == (elements,)
    # The lining is in compression, within its 3 MN/m capacity, pressed on by the rock.
    assert 0 < l.thrust.min() and l.thrust.max() <= 3e6 * (1 + 1e-9)
    assert l.normal_stress.min() < 0


def test_envelope_small_specimen():
    """bbm.envelope() returns envelope.json as a dict: the fits and every run."""
    e = bbm.envelope(width=2.0, height=4.0, confinements=[2e6, 5e6], realizations=1, threads=1)
    assert [r["test"] for r in e["runs"]] == ["ucs", "tension", "biaxial", "biaxial"]
    peaks = {r["sigma3"]: r["peak"] for r in e["runs"] if r["test"] in ("ucs", "biaxial")}
    assert peaks[0.0] < peaks[2e6] < peaks[5e6]
    assert e["hoek_brown"]["valid"] and e["hoek_brown"]["mi"] > 0
    assert e["mohr_coulomb"]["valid"] and 0 < e["mohr_coulomb"]["friction_deg"] < 90
    assert 0 < e["tension"]["over_ucs"] < 0.3


def test_envelope_of_a_model_files_rock():
    """bbm.envelope(model=...): the rock of a model file (here the trigon tunnel's
    trigon blocks and joints) on a small specimen."""
    model = str(SOURCE / "examples/tunnel_trigon.toml")
    e = bbm.envelope(model=model, width=1.5, height=3.0, confinements=[2e6], realizations=1, threads=1)
    assert e["specimen"]["pattern"] == "trigon" and e["specimen"]["model"] == model
    assert e["specimen"]["seed"] == 7  # the model's pattern seed
    assert e["levels"][0]["peak"]["mean"] < e["levels"][1]["peak"]["mean"]


def test_boolean_keywords_reach_flags_and_options():
    """A True keyword is a flag (calibrate's fit_ci) or a boolean option (servo):
    both must reach the program."""
    c = bbm.calibrate(width=1.5, height=3.0, realizations=1, iterations=1, threads=1, target_ci_ratio=0.3,
                      fit_ci=True, servo=True)
    assert c["targets"]["fit_ci"] is True
    assert "weibull_modulus" in c["iterations"][0]
    c = bbm.calibrate(width=1.5, height=3.0, realizations=1, iterations=1, threads=1, fit_ci=False)
    assert c["targets"]["fit_ci"] is False


def test_shear_coulomb_joint():
    """bbm.shear(): a planar 30-degree joint between rigid halves, two normal
    stresses: peaks sigma_n tan 30, a Coulomb fit through the origin, curves as arrays."""
    s = bbm.shear(pattern="single", normal_stress=[2e6, 4e6], max_displacement=3e-4, joint_friction=30.0)
    assert len(s["runs"]) == 2
    for run in s["runs"]:
        assert run["peak_shear_stress"] == pytest.approx(run["normal_stress"] * math.tan(math.radians(30.0)), rel=1e-3)
        curve = run["curve"]
        assert curve["shear_stress"].shape == curve["shear_displacement"].shape
        assert curve["shear_displacement"][-1] >= 3e-4
    assert s["peak_coulomb"]["friction_deg"] == pytest.approx(30.0, abs=0.05)
    with pytest.raises(bbm.InputError, match="--persistence"):
        bbm.shear(pattern="single", persistence=0.5)


def test_shear_barton_bandis_joint():
    """The same keywords as bbm shear's flags: a rough joint peaks at Barton's
    sigma_n tan(phi_r + JRC log10(JCS / sigma_n)) at the normal stress of its peak."""
    s = bbm.shear(pattern="single", joint_law="barton_bandis", joint_jrc=10, joint_jcs=100e6, joint_friction=30,
                  normal_stress=2e6, max_displacement=5e-4)
    run = s["runs"][0]
    sn = run["normal_stress_at_peak"]
    assert sn == pytest.approx(2e6, rel=1e-2)
    assert run["peak_shear_stress"] == pytest.approx(sn * math.tan(math.radians(30 + 10 * math.log10(100e6 / sn))),
                                                     rel=2e-3)
    with pytest.raises(bbm.InputError, match="barton_bandis"):
        bbm.shear(pattern="single", joint_jrc=10)


def test_callback_exception_stops_and_propagates():
    m = bbm.Model(str(INSITU))

    def boom(model):
        if model.steps >= 10:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        m.run(callback=boom, every=10)
    assert m.steps == 10


def test_bad_model_file_raises_input_error_with_key(tmp_path):
    text = INSITU.read_text().replace("size = 0.4", "size = -0.4")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(bbm.InputError) as e:
        bbm.Model(str(path))
    assert e.value.key == "region[0].pattern.size"
    assert e.value.line == text.splitlines().index(next(l for l in text.splitlines() if "size = -0.4" in l)) + 1
    assert "bad.toml" in str(e.value) and "region[0].pattern.size" in str(e.value)
    # The program says the same.
    rc, log = cli("run", path, "--out", tmp_path / "out")
    assert rc == 2 and "region[0].pattern.size" in log


def test_bad_dict_raises_input_error_with_key():
    d = tomllib.loads(INSITU.read_text())
    d["joint_property"][0]["kn"] = -1.0
    with pytest.raises(bbm.InputError) as e:
        bbm.Model.from_dict(d)
    assert e.value.key == "joint_property[0].kn"
    d = tomllib.loads(INSITU.read_text())
    d["solver"]["modee"] = "dynamic"
    with pytest.raises(bbm.InputError, match="solver.modee"):
        bbm.Model.from_dict(d)


def test_ucs_matches_the_program(tmp_path):
    r = bbm.ucs(width=2, height=4, seed=3, max_strain=0.0015)
    rc, log = cli("ucs", "--width", 2, "--height", 4, "--seed", 3, "--max-strain", 0.0015, "--out", tmp_path, "--quiet")
    assert rc == 0, log
    ref = json.loads((tmp_path / "summary.json").read_text())
    assert r["steps"] == ref["steps"]
    assert r["peak_stress"] == ref["peak_stress"] and r["E"] == ref["E"]
    curve = r["curve"]
    assert curve["axial_stress"].shape == curve["axial_strain"].shape == (len(curve["step"]),)
    # Pa and strain: the peak of the curve is the peak reported.
    assert curve["axial_stress"].max() == pytest.approx(r["peak_stress"], rel=1e-12)
    assert 5e9 < r["E"] < 40e9


def test_labtest_options_are_checked_as_flags():
    with pytest.raises(bbm.InputError, match="--kn"):
        bbm.ucs(kn=-1.0)
    with pytest.raises(bbm.InputError, match="--pattren|pattren"):
        bbm.ucs(pattren="trigon")
    with pytest.raises(bbm.InputError, match="--size"):
        bbm.ucs(size=5.0, width=2, height=4)
    # A softening curve is its points, as a model file writes them; checked by the same rules.
    with pytest.raises(bbm.InputError, match="--tension-softening: \\[1\\]\\[0\\]: the curve snaps back"):
        bbm.ucs(tension_softening=[[1.7, 0.5], [1.5, 0.0]])


def test_realizations_give_one_curve_each():
    r = bbm.tension(width=2, height=4, realizations=2, threads=2)
    assert r["realizations"] == 2
    assert len(r["per_realization"]) == 2
    for entry in r["per_realization"]:
        assert entry["curve"]["axial_stress"].size > 10
    assert r["peak_stress"]["mean"] > 0


@pytest.mark.parametrize("script", ["tunnel_seeds.py", "calibration_sweep.py"])
def test_examples_run(script, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    args = [sys.executable, str(SOURCE / "examples/python" / script), "--quick", "--out", str(tmp_path)]
    if script == "tunnel_seeds.py":
        args += ["--seeds", "7", "17", "27"]
    else:
        args += ["--tensile", "2e6", "4e6"]
    done = subprocess.run(args, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    assert pngs == (["cracks.png", "hoop_stress.png"] if script == "tunnel_seeds.py" else ["curves.png", "sweep.png"])
    rows = json.loads(next(tmp_path.glob("*.json")).read_text())
    if script == "calibration_sweep.py":
        # A stronger bond makes a stronger rock.
        assert rows[1]["tensile_strength"] > rows[0]["tensile_strength"]
    else:
        assert len({r["state_hash"] for r in rows}) == 3


def test_unstable_model_raises_numerical_error(tmp_path):
    # A time step far above the stable one: the health checks stop it, as bbm run does (exit 3).
    text = (SOURCE / "examples/verification/pwave_column.toml").read_text()
    text = text.replace("safety = 0.5", "safety = 0.5\ntimestep = 1.0e-4")
    m = bbm.Model._from_text(text, "unstable.toml")
    with pytest.raises(bbm.NumericalError, match="step"):
        m.run()
    assert not m.summary()["complete"]


def test_water_in_the_joints_arrays():
    m = bbm.Model(str(SOURCE / "examples/water/tunnel_below_water_table.toml"), threads=2)
    f = m.flow
    assert f is not None
    # Before any stage: hydrostatic from the water table at y = 100 m, every domain.
    y = f["domain_position"][:, 1]
    assert np.allclose(f["pressure"], 1000.0 * 9.81 * (100.0 - y), rtol=1e-9)
    assert f["pipes"].shape == (len(f["aperture"]), 2)
    c = m.contacts
    assert c.fluid_pressure.shape == (c.count,) and c.aperture.shape == (c.count,)
    assert c.fluid_pressure.max() > 0.9e6
    assert bbm.Model(str(INSITU)).flow is None


def test_static_fatigue_creep_time_and_bond_sections(tmp_path):
    # The static-fatigue example held for a day of creep time (not to its failure).
    text = (SOURCE / "examples/time/static_fatigue.toml").read_text().replace("duration = 3.156e7", "duration = 86400.0")
    path = tmp_path / "day.toml"
    path.write_text(text)
    m = bbm.Model(str(path), threads=2)
    m.run()
    s = m.summary()
    assert s["creep"]["time"] == 86400.0 and "failed_at" not in s["creep"]
    assert s["stages"][-1]["kind"] == "creep" and s["stages"][-1]["converged"]
    section = m.contacts.bond_section
    assert section.shape == (m.contacts.count,)
    assert 0.0 < section.min() < 1.0 and section.max() == 1.0
    assert s["state_hash"] == cli_run(path, tmp_path / "cli")["state_hash"]


def test_events_and_energy_as_numpy(tmp_path):
    """The calibrated tunnel's events ([events]) as arrays, the same catalogue as
    the program's events.csv; the energy account as summary.json's."""
    d = tomllib.loads((SOURCE / "examples/tunnel_voronoi_calibrated.toml").read_text())
    for stage in d["stage"]:
        if stage["name"] == "excavation":
            stage["relax_steps"] = 1500
        if stage["name"] == "failure":
            stage["max_steps"] = 500
    d["solver"]["energy_account"] = True
    path = tmp_path / "tunnel.toml"
    path.write_text(bbm.to_toml(d))
    cli_run(path, tmp_path / "cli")
    m = bbm.Model.from_dict(d, threads=2)
    m.run()
    e = m.events
    n = len(e["time"])
    rows = (tmp_path / "cli" / "events.csv").read_text().strip().splitlines()
    assert n > 0 and n == len(rows) - 1
    assert e["position"].shape == (n, 2) and e["tensor"].shape == (n, 3) and len(e["type"]) == n
    assert set(e["type"]) <= {"tensile", "shear", "implosive"}
    # Hanks and Kanamori's magnitude of the moment (core/events.hpp).
    assert np.allclose(e["magnitude"], (np.log10(e["moment_nm"]) - 9.1) / 1.5)
    assert np.all(e["bonds"] >= 1) and e["bonds"].sum() <= sum(m.cracks.values())
    acc = m.energy
    bal = m.summary()["energy_balance"]
    for k in ("work", "kinetic", "strain", "joints", "damping", "radiated"):
        assert acc[k] == pytest.approx(bal[k], rel=1e-12, abs=1e-9)
    # A model without [events] has none, and a quasi-static one without the account none.
    assert bbm.Model(str(INSITU)).events is None
    assert bbm.Model(str(INSITU)).energy is None
