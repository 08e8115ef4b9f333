"""The one QP core every quadratic program in the project goes through.

Static IK steps (thesis Eq. 4.13), the tangent-space solver of ch. 4 (Eq. 4.10) and
the MoCurves time warp are all small *dense* QPs — tens to a few hundred variables —
solved many times in a row with the same shape while a person drags. For that case a
dense active-set method with a workspace allocated once and the active set carried
from one solve to the next beats an ADMM solver that must re-factorise a KKT system
each call (measured in ``puppetphone bench qp``: DAQP, ProxSuite, PIQP, OSQP on the
real problems). :class:`DenseQP` is that workspace; a solve returns a
:class:`QPResult` whose ``status`` says what happened, and ``x`` is ``None`` only
when there is no usable answer (the caller decides: reject the drag, shrink a trust
region, raise).
"""

from engine.qp.dense import DenseQP, QPResult, QPStatus
from engine.qp.lsq import LeastSquaresQP

__all__ = ["DenseQP", "LeastSquaresQP", "QPResult", "QPStatus"]
