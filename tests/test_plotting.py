"""Every figure draws from a synthetic dataset and saves byte-reproducibly."""
import pytest

import filippov_paper.plotting as plotting
import synthetic

#: every figure (its module's synthetic_dataset: nothing to list here for a new one)
CASES = plotting.figure_ids()


@pytest.mark.parametrize("scene_id", sorted(CASES))
def test_draw_and_save_is_deterministic(tmp_path, scene_id):
    ds = synthetic.dataset(scene_id)
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
        plotting.draw("fig99_nothing", synthetic.dataset("fig08_s0theta"))


def test_missing_variable_is_named():
    ds = synthetic.dataset("fig08_s0theta").drop_vars("s0_root")
    with pytest.raises(KeyError, match="s0_root"):
        plotting.draw("fig08_s0theta", ds)
