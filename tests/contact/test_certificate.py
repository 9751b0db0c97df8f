"""The reason a certified result carries: the certificate's figures, never a stale best residual of the solver."""

from roughpetsc.contact.certificate import KKTReport, certified


def kkt(natural, load_error):
    return KKTReport(natural=natural, complementarity=0.0, min_p=0.0, min_g=0.0, load_error=load_error)


def test_a_stop_whose_answer_passes_quotes_the_certificate():
    reason = "DIVERGED_USER (time limit, best of natural residual, load error 3.7e-07)"
    converged, said = certified(reason, kkt(6.2e-10, 1.9e-11), 1e-8)
    assert converged
    assert said == "DIVERGED_USER (time limit, natural residual 6.2e-10, load error 1.9e-11)"


def test_a_stop_whose_answer_fails_quotes_the_certificate():
    converged, said = certified("DIVERGED_USER (time limit, best natural residual 2e-06)", kkt(3e-6, None), 1e-8)
    assert not converged
    assert said == "DIVERGED_USER (time limit, natural residual 3e-06)"


def test_a_claim_the_certificate_rejects_is_not_certified():
    converged, said = certified("CONVERGED_USER", kkt(1e-8, 5e-7), 1e-8)
    assert not converged
    assert said == "NOT_CERTIFIED (CONVERGED_USER, but on a fresh gap: natural residual 1e-08, load error 5e-07)"


def test_a_converged_solve_keeps_its_reason():
    assert certified("CONVERGED_USER", kkt(5e-9, 1e-12), 1e-8) == (True, "CONVERGED_USER")
