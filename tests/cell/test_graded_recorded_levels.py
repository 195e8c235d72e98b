"""The graded FE cell's estimate on recorded levels of the shipped scene (issue 35: effectivity, no solve).

The levels of ``scripts/graded_effectivity.py`` (``geometries/cells/westergaard_graded.toml`` to its tolerance
``1e-4``, penalty ``k_n = 1e6 E`` and exact contact, one thread: the same figures bit for bit run after run): per
load the headline quantities of the orders solved on the answer's mesh, the records
:func:`~ngcontact.cell.fe.grading_estimate.order_estimate` reads (the first order's changes over the last grading
step, the last order's contact set's move, its edge cells and stiffness record), and the true error of the
answer in its measure against the script's oracle (penalty: the same model graded 9 levels at order 7; exact:
Westergaard's closed forms moved by the layers' finite depth), on the rows the script judges.  ``exact 0.05 level
4`` is the check at grading level 4 that the refinement rejected and graded further: its estimate must bound the
error of that level's last order too, or the run would stop there.

Every estimate is at least its true error, and at most ten times it except the three rows of :data:`LOOSE`,
which sharper rules tried on these levels could not bring within ten without taking another below one:

* ``penalty 0.05`` stiffness (42): its orders' errors ``+4.0e-5, +1.2e-6, -2.1e-8`` (relative) change sign
  between the last two orders, the last value landing on the limit; the orders' tail alone would be 5.4 times
  its error, the grading's tail of the change at order 3 (``1.2e-5``) adds ``7.8e-7``.  The larger of the two
  tails instead of their sum leaves 36 here and takes ``penalty 0.5``'s stiffness to 0.77 (its orders' errors
  ``5.2e-6, 1.3e-6, 7.4e-7`` stall: it needs both); the grading tail times the orders' contraction, 6.5 here and
  0.57 there.
* ``penalty 0.5`` closure (14): the orders' errors ``-1.7e-5, -1.8e-7, -3.9e-10`` contract by 0.010 and then
  0.0023, faster than the one ratio of changes (0.010) shows, so its geometric tail alone is 4.6 times the
  error and the safety 3 of the orders' rule makes 14; ``penalty 0.05``'s closure, whose contraction slows
  (0.021, then 0.026), needs the safety: without it 0.83, and ``exact 0.5``'s 0.55 (1.1 with a safety 2).
* ``exact 0.2`` stiffness (10.4): the grading tail of the change at order 3 (``5.1e-5``) bounds that order's
  edges (its error ``7.2e-5``), which orders 4 and 5 reduce to ``4.9e-6``; the contact set's share beside it
  (``4.7e-5``) alone would be 9.6, but the same share alone is 1.13 at ``exact 0.5`` and, at the rejected
  level 4 of ``exact 0.05``, 0.82 (the run then stops there).
"""
import pytest

from ngcontact.cell.fe.grading_estimate import order_estimate

#: the rows above ten times their error, and why (module docstring)
LOOSE = {("penalty 0.05", "normal_stiffness"), ("penalty 0.5", "mean_closure"), ("exact 0.2", "normal_stiffness")}
NAMES = ("contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n", "coefficient_g_n")

LEVELS = {
    "penalty 0.05": {
        "grading_change": 1.4397173013852571e-05,
        "penalty": True,
        "k_n": 1000000.0,
        "values": [
            (0.14356041447346776, 0.0019977929840160934, 0.5762251394399195, 143560.4144734682, 48.17642626342755),
            (0.14356835296467654, 0.0019978694981176042, 0.5762027796123651, 143568.3529646764, 48.184364547049874),
            (0.14356862018015837, 0.0019978711279510916, 0.576202084835909, 143568.6201801566, 48.184631770515956),
        ],
        "changes": {
            "normal_stiffness": 6.729873089028615e-06,
            "coefficient_k_n": 14.39717301458586,
            "coefficient_g_n": 0.014394594689669304,
        },
        "set_move": 2.2602879702571244e-05,
        "edge_cells": [[8.639018770337237e-06, 0.0010002544766069652], [8.52037918641635e-06, 0.0010002600797878814]],
        "stiffness_edges": None,
        "true_error": {
            "contact_fraction": 1.7756750739228444e-07,
            "mean_closure": 2.1442662684887366e-08,
            "normal_stiffness": 2.1462693738445444e-08,
            "coefficient_k_n": 1.2368128208386283e-06,
            "coefficient_g_n": 3.685270089373201e-06,
        },
    },
    "penalty 0.5": {
        "grading_change": 1.4433342108211011e-05,
        "penalty": True,
        "k_n": 1000000.0,
        "values": [
            (0.4999844377788429, 0.008465603600835982, 2.4903197498246694, 499984.4377788397, 1816.7455199256308),
            (0.500002196047037, 0.008465748909303801, 2.4903101385771143, 500002.1960470372, 1816.9230987109465),
            (0.5000027871869805, 0.00846575038954334, 2.490308643731557, 500002.7871869774, 1816.9290101556835),
        ],
        "changes": {
            "normal_stiffness": 2.124215060650414e-05,
            "coefficient_k_n": 14.433342108910438,
            "coefficient_g_n": 0.1443232347473895,
        },
        "set_move": 3.278275024343191e-05,
        "edge_cells": [[8.968095947387011e-06, 0.010000242553113223], [9.005459579269903e-06, 0.010000327139323407]],
        "stiffness_edges": None,
        "true_error": {
            "contact_fraction": 3.6412065151925077e-07,
            "mean_closure": 3.943688192492696e-10,
            "normal_stiffness": 7.381085901612244e-07,
            "coefficient_k_n": 7.282372479613588e-07,
            "coefficient_g_n": 2.0040621852813606e-06,
        },
    },
    "exact 0.2": {
        "grading_change": 7.396642576873447e-05,
        "penalty": False,
        "k_n": 1000.0,
        "values": [
            (0.29514524084901417, 0.005218682608544679, 1.0725943268359737, 295.1452408490118, 0.40510529183015104),
            (0.29516577298555885, 0.005218871705869292, 1.0725240136401233, 295.16577298555836, 0.4051874143351714),
            (0.29516608064654803, 0.005218876048071904, 1.0725225315713494, 295.1660806465466, 0.4051886449580144),
        ],
        "changes": {
            "normal_stiffness": 0.000823359833018511,
            "coefficient_k_n": 0.0739664257675372,
            "coefficient_g_n": 0.0002957105993248166,
        },
        "set_move": 9.480622330071409e-05,
        "edge_cells": [[7.812500000001221e-05, 0.004003028047656707], [9.719750258185833e-05, 0.0040048896430321355]],
        "stiffness_edges": {"slope": 8.039231876286046, "spread": 0.0},
        "true_error": {
            "contact_fraction": 1.1719395174858427e-06,
            "mean_closure": 2.268243904541943e-08,
            "normal_stiffness": 4.9194439803609925e-06,
            "coefficient_k_n": 3.970441035488618e-06,
            "coefficient_g_n": 1.1569231250648078e-05,
        },
    },
    "exact 0.5": {
        "grading_change": 2.7861160676767582e-05,
        "penalty": False,
        "k_n": 1000.0,
        "values": [
            (0.4999806557889701, 0.008465556028220864, 2.4905880642418596, 499.98065578896757, 1.8167077021378084),
            (0.49999888076038923, 0.008465733557036316, 2.4905129255201044, 499.9988807603881, 1.8168899458108634),
            (0.49999800459782895, 0.008465736234417603, 2.490228122007144, 499.9980045978264, 1.8168811842188841),
            (0.49999905321309956, 0.00846573626667343, 2.490220714950912, 499.999053213099, 1.816891670332076),
        ],
        "changes": {
            "normal_stiffness": 0.0032272517827656166,
            "coefficient_k_n": 0.02786116067727562,
            "coefficient_g_n": 0.00027868108742823416,
        },
        "set_move": 6.75753136855084e-05,
        "edge_cells": [[7.812499999998446e-05, 0.01000301380749478], [7.812500000003997e-05, 0.01000243006668587]],
        "stiffness_edges": {"slope": 21.86361278742997, "spread": 0.0},
        "true_error": {
            "contact_fraction": 9.807854612908784e-07,
            "mean_closure": 1.0558967411640385e-10,
            "normal_stiffness": 3.5116305589662686e-05,
            "coefficient_k_n": 1.961574638140498e-06,
            "coefficient_g_n": 5.3981290164758685e-06,
        },
    },
    "exact 0.05 level 4": {
        "grading_change": 6.986708400219532e-05,
        "penalty": False,
        "k_n": 1000.0,
        "values": [
            (0.14355914961288158, 0.0019978120977495635, 0.5762741777983745, 143.55914961288198, 0.048175161729002186),
            (0.1435628667589648, 0.0019978653037464817, 0.576230705598938, 143.56286675896507, 0.0481788783927796),
            (0.1435643845878845, 0.0019978662741963944, 0.5762257591954011, 143.56438458788412, 0.04818039616634481),
        ],
        "changes": {
            "normal_stiffness": 0.0011958444158155501,
            "coefficient_k_n": 0.06986708400125963,
            "coefficient_g_n": 6.991377791387698e-05,
        },
        "set_move": 6.463210900020666e-05,
        "edge_cells": [[7.812499999999833e-05, 0.0010016053080047673], [7.812500000003997e-05, 0.0010001131635196735]],
        "stiffness_edges": {"slope": 2.9155897024362654, "spread": 0.0},
        "true_error": {
            "contact_fraction": 1.9165599236536934e-06,
            "mean_closure": 1.1737453609495362e-08,
            "normal_stiffness": 3.9523345168097725e-05,
            "coefficient_k_n": 1.3349828577210257e-05,
            "coefficient_g_n": 3.977831028230927e-05,
        },
    },
}


def _orders(case: dict) -> list[dict]:
    """The recorded orders as :func:`order_estimate` reads them: every entry the case's records (the first
    order's changes and the last's contact set, edge cells and stiffness record are the ones read)."""
    keep = ("penalty", "k_n", "set_move", "edge_cells", "stiffness_edges", "changes")
    return [dict({k: case[k] for k in keep}, headline=dict(zip(NAMES, values)), grading_ratio=None)
            for values in case["values"]]


@pytest.mark.parametrize("key", sorted(LEVELS))
def test_the_graded_estimate_bounds_the_recorded_errors_within_ten_times_but_the_diagnosed_rows(key):
    case = LEVELS[key]
    estimate, _ = order_estimate(_orders(case), case["grading_change"])
    for name, error in case["true_error"].items():
        assert estimate[name] >= error, (key, name, estimate[name], error)
        if (key, name) not in LOOSE:
            assert estimate[name] <= 10.0 * error, (key, name, estimate[name], error)
