"""Every figure draws from a synthetic dataset and saves byte-reproducibly."""
import pytest

import filippov_paper.plotting as plotting
import synthetic

CASES = {"fig01_slidesketch": synthetic.fig01, "fig02_cases": synthetic.fig02, "fig03_grazingsketch": synthetic.fig03, "fig04_retmaps": synthetic.fig04, "fig05_thetalt0mfs": synthetic.fig05, "fig06_sgraph": synthetic.fig06,
         "fig07_pdm_theta_neg": synthetic.fig07, "fig08_s0theta": synthetic.fig08,
         "fig09_pdm_theta_pos": synthetic.fig09, "fig10_dfo": synthetic.fig10,
         "fig11_dfo_retmaps": synthetic.fig11}


@pytest.mark.parametrize("scene_id", sorted(CASES))
def test_draw_and_save_is_deterministic(tmp_path, scene_id):
    ds = CASES[scene_id]()
    outputs = []
    for run in ("one", "two"):
        pdf, png = tmp_path / f"{run}.pdf", tmp_path / f"{run}.png"
        plotting.save(plotting.draw(scene_id, ds), pdf, png)
        outputs.append((pdf.read_bytes(), png.read_bytes()))
    (pdf1, png1), (pdf2, png2) = outputs
    assert pdf1.startswith(b"%PDF")
    assert png1.startswith(b"\x89PNG")
    assert pdf1 == pdf2
    assert png1 == png2
    assert b"CreationDate" not in pdf1
    assert not list(tmp_path.glob(".*.tmp")), "temporary files left behind"


def test_unknown_scene_is_rejected():
    with pytest.raises(ValueError, match="no figure module"):
        plotting.draw("fig99_nothing", synthetic.fig08())


def test_missing_variable_is_named():
    ds = synthetic.fig08().drop_vars("s0_root")
    with pytest.raises(KeyError, match="s0_root"):
        plotting.draw("fig08_s0theta", ds)
