"""What a rotation fit returns: the fitted state and moment ratios, their covariance, residuals, a plot."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class FitResult:
    """A converged fit (a fit that did not converge raises :class:`spinorbit.fit.FitNotConvergedError`).

    Attributes
    ----------
    state : RotationState
        The fitted state at ``epoch`` on ``body`` (the body with the fitted moment ratios).
    body : RigidBody
    epoch : Time
    parameter_names : tuple of str
        ``δθx, δθy, δθz`` (rad, the attitude about the fitted one, principal axes), ``ωx, ωy, ωz``
        (rad/day, principal axes) and, when fitted, ``A/C, B/C``.
    values : ndarray
        The fitted parameters (δθ = 0 by construction: the attitude is the fitted one).
    covariance : ndarray
        Formal covariance (J^T J)^-1 of the parameters from the whitened Jacobian at the solution (the
        σ are taken as given; scale by ``reduced_chi2`` for an empirical one).
    standard_errors, correlation : ndarray
    residuals : ndarray
        Whitened residuals (model − observed)/σ, all observations in order.
    residual_times : ndarray
        Days since ``epoch`` of each residual component; ``residual_kinds`` its observation type.
    chi2, dof, reduced_chi2
        Σ r², residual components minus parameters, and their ratio (None when dof = 0).
    condition_number : float
        Of the column-normalised whitened Jacobian (``condition_threshold`` refused above).
    unseparated : tuple
        (name, name, correlation) of every pair with |correlation| above ``correlation_threshold``.
    converged : bool
        Always True here (the message of least_squares in ``message``).
    backend, nfev, message, starts
        The STM back end, function evaluations, least_squares' message, and (start phase in rad, cost,
        status) of every multi-start run.
    """

    state: object
    body: object
    epoch: object
    parameter_names: tuple
    values: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    residual_times: np.ndarray
    residual_kinds: tuple
    chi2: float
    dof: int
    condition_number: float
    correlation_threshold: float
    unseparated: tuple
    converged: bool
    backend: str
    nfev: int
    message: str
    starts: tuple = field(default=())

    @property
    def standard_errors(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    @property
    def correlation(self) -> np.ndarray:
        s = self.standard_errors
        return self.covariance / np.outer(s, s)

    @property
    def reduced_chi2(self):
        return None if self.dof == 0 else self.chi2 / self.dof

    @property
    def moment_ratios(self) -> tuple[float, float]:
        """(A/C, B/C) of the fitted body (principal moments)."""
        big_a, big_b, big_c = self.body.principal_moments
        return big_a / big_c, big_b / big_c

    def report(self) -> str:
        """A plain-text summary: parameters ± σ, χ², the condition number and any unseparated pairs."""
        lines = [f"fit ({self.backend}, {self.nfev} evaluations): {self.message}",
                 f"chi2 = {self.chi2:.4g} for {self.dof} degrees of freedom"
                 + (f" (reduced {self.reduced_chi2:.4g})" if self.dof else ""),
                 f"condition number of the normalised Jacobian: {self.condition_number:.3g}"]
        for name, value, sigma in zip(self.parameter_names, self.values, self.standard_errors):
            lines.append(f"  {name:>6} = {value: .10g} ± {sigma:.3g}")
        if self.unseparated:
            lines.append(f"the data do not separate (|correlation| > {self.correlation_threshold}):")
            lines += [f"  {a} and {b}: correlation {c:+.6f}" for a, b, c in self.unseparated]
        return "\n".join(lines)

    def plot(self, ax=None):
        """Whitened residuals against days since the epoch, one marker per observation type; returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 3.5))
        kinds = np.array(self.residual_kinds)
        for kind, marker in zip(dict.fromkeys(self.residual_kinds), "osd^v<>"):
            chosen = kinds == kind
            ax.plot(self.residual_times[chosen], self.residuals[chosen], marker, ms=4, ls="none", label=kind)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("days since the fit epoch (TDB)")
        ax.set_ylabel("(model − observed) / σ")
        ax.set_title(f"rotation fit: χ²/dof = {self.chi2:.1f}/{self.dof}")
        ax.legend(fontsize="small")
        return ax
