"""Calibration: calibrate and evaluate, and their results."""

from __future__ import annotations

import os
import re
import warnings
from typing import Any, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np

from . import _fastcal
from ._fastcal import CalibrationError, Dataset, InputError, Model

from ._common import PathLike, _DICT_SPEC, _spec_argument
from .dataset import read_dataset


class CalibrationResult:
    """What fastcal.calibrate found (docs/calibration.md explains each part).

    Attributes:
        parameters: one dict per parameter the spec names, in spec order: name, unit,
            free, consider, initial, estimate, sigma (formal: stated noise, independent
            samples), sigma_total (the uncertainty to quote) with its parts
            sigma_statistical (the formal one widened by misfit and time-correlated
            residuals; widening = their ratio; tau) and sigma_systematic (from consider
            parameters; systematic_by_group), prior_mean, prior_sigma (None without a
            prior), note. Values in the spec's units (kN for sensor biases).
        estimates: name -> estimate, every parameter the spec names.
        sigma, sigma_total: name -> formal and total standard deviation, free ones.
        free_names: the free parameters, in the order of `correlation`'s rows.
        correlation: correlation matrix of the free estimates (total covariance), (k, k).
        outliers: the gross errors kept out of the fit, in file order: dicts of line,
            cable (1-6), reading ('tension', or 'length' with the lengths in the fit),
            measured_kN and predicted_kN (a length: measured_m, predicted_m),
            residual_sigma, held_out.
        lengths: with the lengths in the fit (spec noise.length_sigma_m), a dict of
            sigma_m and per cable (6,) initial_rms_m, calibrated_rms_m,
            calibrated_mean_m (model minus measured); None without.
        worst_readings: the fitted readings with the largest |residual| / sigma.
        misfit_ranking: fixed parameters by the chi-square decrease freeing each would
            bring (name, expected_chi_square_decrease, significant); misfit_threshold
            is what white noise alone reaches.
        rms_kN: variant -> RMS of model minus measured per cable, (6,), on the fitted
            samples: the initial model at each attitude the data has, and the
            calibrated one (the paper's Table 6). holdout_rms_kN: the same on the
            held-out samples (variants with some). cross_validation_rms_kN: the block
            cross-validation's, or None.
        evaluation: variant -> the full statistics (fit, holdout: samples, rms_kN,
            mean_kN, max_abs_kN, rms_percent, max_abs_percent) and predicted_kN (n, 6).
        verdict: 'ok', 'noise overstated', 'misfit' or 'failed'; verdict_text says why.
        reduced_chi_square, converged, iterations, termination, notes,
        strong_correlations, budget (dict), seconds.
        model: the calibrated Model.
        held_out: per sample, held out of the fit (list of bool).
        gross_error_mask: per sample and cable, a reading kept out, (n, 6) bool.
        sessions: a joint fit's session labels (spec sessions.separate), else empty;
            session_models: label -> the calibrated Model of that session;
            session_differences: each separate parameter's change between consecutive
            sessions, dicts of name, unit, from, to, difference, sigma_total.
        change_scan: the scan (spec change_scan) as a dict (parameters, time_s,
            statistic, threshold, significance, widening, min_segment_samples), or None;
            changes: the changes found, dicts of time_s, line, sample, statistic,
            p_value, shifts and shift_sigmas (name -> value, later minus earlier).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.parameters: List[Dict[str, Any]] = raw["parameters"]
        self.estimates: Dict[str, float] = {p["name"]: p["estimate"] for p in self.parameters}
        free = [p for p in self.parameters if p["free"]]
        self.sigma: Dict[str, float] = {p["name"]: p["sigma"] for p in free}
        self.sigma_total: Dict[str, float] = {p["name"]: p["sigma_total"] for p in free}
        self.free_names: List[str] = raw["free_names"]
        self.correlation: np.ndarray = raw["correlation"]
        self.outliers: List[Dict[str, Any]] = raw["outliers"]
        self.worst_readings: List[Dict[str, Any]] = raw["worst_readings"]
        self.misfit_ranking: List[Dict[str, Any]] = raw["misfit_ranking"]
        self.misfit_threshold: float = raw["misfit_threshold"]
        self.evaluation: Dict[str, Dict[str, Any]] = raw["evaluation"]
        self.rms_kN: Dict[str, np.ndarray] = {
            name: v["fit"]["rms_kN"] for name, v in self.evaluation.items()
        }
        self.holdout_rms_kN: Dict[str, np.ndarray] = {
            name: v["holdout"]["rms_kN"]
            for name, v in self.evaluation.items()
            if v["holdout"] is not None
        }
        self.cross_validation_rms_kN: Optional[np.ndarray] = raw["cross_validation_rms_kN"]
        self.lengths: Optional[Dict[str, Any]] = raw["lengths"]
        self.verdict: str = raw["verdict"]
        self.verdict_text: str = raw["verdict_text"]
        self.notes: List[str] = raw["notes"]
        self.strong_correlations: List[str] = raw["strong_correlations"]
        self.budget: Dict[str, Any] = raw["budget"]
        self.model: Model = raw["model"]
        self.held_out: List[bool] = raw["held_out"]
        self.gross_error_mask: np.ndarray = raw["gross_error_mask"]
        self.reduced_chi_square: float = raw["reduced_chi_square"]
        self.converged: bool = raw["converged"]
        self.iterations: int = raw["iterations"]
        self.termination: str = raw["termination"]
        self.num_residuals: int = raw["num_residuals"]
        self.num_fit_samples: int = raw["num_fit_samples"]
        self.seconds: float = raw["seconds"]
        self.ceres_report: str = raw["ceres_report"]
        self.sessions: List[str] = raw["sessions"]
        self.session_models: Dict[str, Model] = raw["session_models"]
        self.session_differences: List[Dict[str, Any]] = raw["session_differences"]
        self.change_scan: Optional[Dict[str, Any]] = raw["change_scan"]
        self.changes: List[Dict[str, Any]] = raw["changes"]

    def report_html(self, path: Optional[PathLike] = None) -> str:
        """The calibration's report as the command line writes report.html (plots
        inline, self-contained); written to `path` too when given (refused if it exists).
        In a notebook: IPython.display.HTML(result.report_html())."""
        return self._report_text("html", path)

    def report_markdown(self, path: Optional[PathLike] = None) -> str:
        """The report as Markdown (report.md); written to `path` too when given."""
        return self._report_text("md", path)

    def _report_text(self, kind: str, path: Optional[PathLike]) -> str:
        state, data, data_name = self._report
        text = _fastcal.calibration_report(state, data, kind, data_name)
        if path is not None:
            # As the command line publishes: a temporary renamed into place, never over a
            # file (FileExistsError); a failure (a full disk) leaves nothing at `path`.
            _fastcal.write_new_file(os.fspath(path), text)
        return text

    def to_dataframe(self) -> Any:
        """The parameters as a pandas DataFrame, one row per parameter (index: its name):
        unit, free, estimate, sigma, sigma_total, sigma_statistical, sigma_systematic,
        prior_mean, prior_sigma, note."""
        import pandas

        keys = ["unit", "free", "consider", "initial", "estimate", "sigma", "sigma_total",
                "sigma_statistical", "sigma_systematic", "prior_mean", "prior_sigma", "note"]
        rows = [{k: p.get(k) for k in keys} for p in self.parameters]
        return pandas.DataFrame(rows, index=[p["name"] for p in self.parameters])

    def __repr__(self) -> str:
        shown = ", ".join(
            f"{name} = {self.estimates[name]:.6g} +- {self.sigma_total[name]:.2g}"
            for name in self.free_names
        )
        return f"<fastcal.CalibrationResult: {self.verdict}; {shown}>"


def _model_and_data(
    model: Optional[Union[Model, PathLike]], data: Union[Dataset, PathLike]
) -> Tuple[Model, Dataset]:
    """The model (nominal, or loaded from its file) and the data (read with the model's
    joint columns when given as a path)."""
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    if not isinstance(data, Dataset):
        data = read_dataset(data, model=model)
    return model, data


def calibrate(
    spec: Union[PathLike, Mapping[str, Any]],
    data: Union[Dataset, PathLike],
    model: Optional[Union[Model, PathLike]] = None,
    quiet: bool = False,
) -> CalibrationResult:
    """Estimates model parameters from measured poses and tensions (docs/calibration.md).

    What `fastcal calibrate` does, without writing files: the fit, its uncertainty
    budget, gross errors, the misfit ranking, and the RMS tables of the initial and the
    calibrated model (exact statics).

    Args:
        spec: a calibration spec file, or the same content as a dict, e.g.
            {"format": "fastcal-calibration-spec-1",
             "parameters": {"mass_centre_m": {"x": {"free": True}, "y": {"free": True}}}}.
        data: a Dataset, or the path of a telemetry CSV.
        model: the starting model (a Model or a model file); None for Model.nominal().
        quiet: no progress lines (one per solver iteration, "fastcal.calibrate: ..." on
            sys.stderr, which a notebook shows).

    Returns:
        A CalibrationResult. A fit whose verdict is 'failed' is returned, with a
        RuntimeWarning, as the command line writes it with a warning.

    Raises:
        InputError: a bad spec, dataset or model file (file, line, key named).
        CalibrationError: refused or failed; `status` is 'undetermined' (the data cannot
            determine the free set: the message names the combination), 'infeasible' (the
            model cannot hold a sample's pose: the line is named), 'solver failed' or
            'mostly gross errors'.
    """
    data_name = os.fspath(data) if not isinstance(data, Dataset) else "Dataset"
    model, data = _model_and_data(model, data)
    spec_text, is_text, source = _spec_argument(spec)
    try:
        raw, state = _fastcal.calibrate(model, spec_text, is_text, source, data, quiet)
    except InputError as error:
        # A dict has no lines: its messages name the key path alone.
        message = re.sub(rf"^{re.escape(_DICT_SPEC)}:\d+: ", f"{_DICT_SPEC}: ", str(error))
        raise InputError(message) from None
    result = CalibrationResult(raw)
    result._report = (state, data, data_name)  # for report_html() and report_markdown()
    if result.verdict == "failed":
        warnings.warn(f"the fit failed: {result.verdict_text}", RuntimeWarning, stacklevel=2)
    return result


def evaluate(
    data: Union[Dataset, PathLike],
    model: Optional[Union[Model, PathLike]] = None,
    method: str = "exact",
) -> Dict[str, Dict[str, Any]]:
    """Model minus measured tension statistics per cable, as `fastcal evaluate` prints.

    Returns:
        variant -> statistics, for 'model, planned attitude' (when the data has it) and
        'model, measured attitude': {'fit': {'samples', 'rms_kN', 'mean_kN',
        'max_abs_kN', 'rms_percent', 'max_abs_percent', 'excluded'}, 'holdout': None,
        'predicted_kN': (n, 6)}. The model's sensor gains and biases are applied.

    Raises:
        InputError: a bad file or method. CalibrationError ('infeasible'): the model
        cannot hold a sample's pose (its line is named).
    """
    model, data = _model_and_data(model, data)
    return _fastcal.evaluate(model, data, method)
