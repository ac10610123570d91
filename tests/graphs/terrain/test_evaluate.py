import pytest

from seminspect.graphs.terrain.evaluate import (
    ClassMatch,
    ObjectQuality,
    ObjectScores,
    PlaceQuality,
    PlaceScores,
    TerrainQuality,
    match_class,
    prompt_name,
)
from seminspect.mapping.formats.semantickitti import label_table

KITTI = sorted(set(label_table().names.values()))


def test_a_prompt_spells_a_class_name_without_its_filler() -> None:
    assert prompt_name("image of a car") == "car"
    assert prompt_name("An image of the Other_Vehicle") == "other vehicle"
    assert prompt_name("  a photo of an   apple tree ") == "apple tree"


def test_a_prompt_naming_a_class_maps_to_it_whatever_the_similarity(fake_encoder) -> None:
    # 'trunk' names a SemanticKITTI class; the caption vocabulary also lists it for 'tree'
    match = match_class(fake_encoder, "trunk", KITTI, threshold=0.99)
    assert (match.truth, match.by) == ("trunk", "name")
    caption_similarity = (
        fake_encoder.encode_text(["trunk"])[0] @ fake_encoder.encode_text(["trunk, tree trunk"])[0]
    )
    assert match.similarity == pytest.approx(float(caption_similarity), abs=1e-6)
    assert match_class(fake_encoder, "image of an other-vehicle", KITTI, 0.45).truth == (
        "other-vehicle"
    )


def test_a_synonym_of_one_class_maps_to_it_and_a_shared_one_by_similarity(fake_encoder) -> None:
    classes = ["tree", "car", "grass"]
    assert match_class(fake_encoder, "lawn", classes, 0.99).to_json() == {
        "ground_truth_class": "grass",
        "class_chosen_by": "alias",
        "class_similarity": pytest.approx(
            float(fake_encoder.encode_text(["lawn"])[0] @ fake_encoder.encode_text(
                ["grass, lawn, turf"])[0]), abs=1e-6),
    }  # fmt: skip
    # 'lorry' is a synonym of 'truck' alone here; 'asphalt' of both 'road' and 'parking' (and a
    # class of its own when present)
    assert match_class(fake_encoder, "lorry", ["truck", "car", "road"], 0.99).by == "alias"
    shared = match_class(fake_encoder, "asphalt", ["road", "parking", "car"], 0.0)
    assert shared.by == "similarity" and shared.truth in ("road", "parking")
    assert match_class(fake_encoder, "asphalt", ["road", "asphalt"], 0.99).truth == "asphalt"


def test_without_a_name_the_most_similar_caption_must_reach_the_threshold(fake_encoder) -> None:
    classes = ["tree", "car", "grass"]
    boat = match_class(fake_encoder, "image of a boat", classes, 0.45)
    assert boat.truth is None and boat.by == "none" and boat.similarity < 0.45
    assert match_class(fake_encoder, "image of a car", [], 0.45).to_json() == {
        "ground_truth_class": None,
        "class_chosen_by": "none",
        "class_similarity": None,
    }
    automobile = match_class(fake_encoder, "a red automobile parked", classes, 0.2)
    assert automobile.truth == "car" and automobile.by == "similarity"


def test_quality_records_are_flat_per_prompt_with_the_class_first() -> None:
    car = ClassMatch("car", "name", 0.5)
    scores = ObjectScores(0.3, predicted=4, ground_truth=2, matched=2, mean_iou=0.8)
    trunk = ObjectQuality(ClassMatch("trunk", "name", 0.9), unscored="no instances of 'trunk'")
    assert list(trunk.to_json()) == [*car.to_json(), "unscored"]
    assert ObjectQuality(ClassMatch(None, "none", 0.1)).to_json() == {
        "ground_truth_class": None,
        "class_chosen_by": "none",
        "class_similarity": 0.1,
    }
    places = PlaceScores("grass", 1, 1, 1, 5, 0, float("inf"))
    quality = TerrainQuality(
        {"image of a car": ObjectQuality(car, scores)},
        {"grass": PlaceQuality(ClassMatch("grass", "name", 0.8), 0.99, places)},
    )
    record = quality.to_json()
    assert record["objects"]["image of a car"] == {**car.to_json(), **scores.to_json()}
    assert record["objects"]["image of a car"]["precision"] == 0.5
    grass = record["places"]["grass"]
    assert list(grass)[:5] == [*car.to_json(), "points_on_terrain", "terrain"]
    assert grass["worst_offset"] is None and grass["all_connected"] is True
