"""Figure of the material fits (paper B Fig. 2a)."""

import numpy as np
import pytest

from softbend.materials import TensileTest, Yeoh, fit_models, load_shipped
from softbend.reports.material_figures import fit_figure

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_fit_figure_writes_a_png(tmp_path):
    test = load_shipped("dragon-skin-30")
    results = fit_models(test, max_stretch=4.0)
    path = fit_figure(test, results, tmp_path / "sub" / "fit.png")
    assert path == tmp_path / "sub" / "fit.png"
    assert path.read_bytes()[:8] == PNG_MAGIC
    # Results as a sequence, strain on the abscissa.
    other = fit_figure(test, list(results.values()), tmp_path / "strain.png", x_axis="strain")
    assert other.stat().st_size > 10_000


def test_fit_figure_for_user_data_and_bad_input(tmp_path):
    strain = np.linspace(0.0, 3.0, 30)
    stress = Yeoh(c10_mpa=0.1, c20_mpa=0.01).uniaxial_nominal_stress_mpa(1.0 + strain)
    test = TensileTest("mine", "My rubber", strain, stress)
    results = fit_models(test, "yeoh")
    assert fit_figure(test, results, tmp_path / "fit.png").is_file()
    with pytest.raises(ValueError, match=r"^x_axis: must be one of"):
        fit_figure(test, results, tmp_path / "bad.png", x_axis="time")
    with pytest.raises(ValueError, match="at least one fit"):
        fit_figure(test, {}, tmp_path / "bad.png")
    assert not (tmp_path / "bad.png").exists()
