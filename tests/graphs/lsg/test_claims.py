import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.claims import Claim, TargetClaims
from seminspect.graphs.lsg.graph import LayeredSemanticGraph


def test_a_claimed_target_is_taken_from_the_other_robot_but_not_from_the_claimant() -> None:
    claims = TargetClaims()
    claims.claim("car-0", "explorer", 10.0)
    assert claims.taken_from("inspector", 10.0) == {"car-0"}
    assert claims.taken_from("inspector", 1e6) == {"car-0"}  # open: held whatever the time
    assert claims.taken_from("explorer", 10.0) == set()


def test_a_released_claim_still_holds_for_a_clock_earlier_than_its_release() -> None:
    claims = TargetClaims()
    claims.claim("car-0", "explorer", 10.0)
    claims.release("car-0", 250.0)
    assert claims.taken_from("inspector", 249.9) == {"car-0"}
    assert claims.taken_from("inspector", 250.0) == set()
    claims.claim("car-0", "inspector", 250.0)  # free once released, on the taker's clock
    assert claims.history == [
        Claim("car-0", "explorer", 10.0, 250.0),
        Claim("car-0", "inspector", 250.0),
    ]


def test_claiming_a_target_another_robot_holds_is_an_error() -> None:
    claims = TargetClaims()
    claims.claim("car-0", "explorer", 10.0)
    claims.release("car-0", 40.0)
    with pytest.raises(InvalidInputError, match=r"car-0 is claimed by explorer at t=20\.0 s"):
        claims.claim("car-0", "inspector", 20.0)


def test_releasing_a_target_nobody_holds_is_an_error() -> None:
    claims = TargetClaims()
    with pytest.raises(InvalidInputError, match="not claimed"):
        claims.release("car-0", 1.0)
    claims.claim("car-0", "explorer", 0.0)
    claims.release("car-0", 1.0)
    with pytest.raises(InvalidInputError, match="not claimed"):
        claims.release("car-0", 2.0)


def test_every_graph_starts_with_no_claims() -> None:
    graph = LayeredSemanticGraph()
    assert graph.claims.history == [] and graph.claims.taken_from("inspector", 0.0) == set()
