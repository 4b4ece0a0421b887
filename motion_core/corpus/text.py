"""Natural-language captions for corpus actions: several templates and paraphrases each.

Side, direction, count, speed and amplitude words always come from the action's labels, so
the text never contradicts the motion ("left" is the body's own left).
"""

from __future__ import annotations

import numpy as np

from .actions import REGISTERED, Spec

WHO = ["a person", "someone", "a man", "a woman", "the person", "a figure", "the man", "the woman"]
COUNT = {1: "once", 2: "twice", 3: "three times", 4: "four times", 5: "five times", 6: "six times"}
COUNT.update({7: "seven times", 8: "eight times"})
NUM = {1: "one", 2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight"}
SPEED_ADV = {"slow": ["slowly", "at a slow pace", "leisurely"], "fast": ["quickly", "briskly", "fast"], "normal": [""]}
DIR_PHRASE = {
    "forward": ["forward", "straight ahead", "forwards"],
    "left": ["to the left", "towards the left", "to their left"],
    "right": ["to the right", "towards the right", "to their right"],
    "forward-left": ["diagonally forward to the left", "forward and to the left", "diagonally to the left"],
    "forward-right": ["diagonally forward to the right", "forward and to the right", "diagonally to the right"],
    "backward": ["backwards", "backward", "in reverse"],
}
ARM = {
    "left": ["the left arm", "the left hand"],
    "right": ["the right arm", "the right hand"],
    "both": ["both arms", "both hands"],
}
LEG = {"left": ["the left leg", "the left foot"], "right": ["the right leg", "the right foot"]}

TEMPLATES: dict[str, list[str]] = {
    "walk": [
        "{who} walks {dir}{spd}",
        "{who} is walking {dir}{spd}",
        "{who} takes a walk {dir}{spd}",
        "{who} strolls {dir}{spd}",
    ],
    "jog": ["{who} jogs {dir}{spd}", "{who} is jogging {dir}{spd}", "{who} runs at an easy pace {dir}"],
    "run": ["{who} runs {dir}{spd}", "{who} is running {dir}{spd}", "{who} sprints {dir}"],
    "walk_backward": ["{who} walks backwards{spd}", "{who} steps backwards{spd}", "{who} is walking in reverse{spd}"],
    "sidestep": ["{who} sidesteps {dir}", "{who} shuffles sideways {dir}", "{who} steps sideways {dir}"],
    "turn": [
        "{who} walks and turns {side} by {angle} degrees",
        "{who} walks forward while turning {angle} degrees {side}",
        "{who} walks in a curve, turning {side} by {angle} degrees",
    ],
    "circle": [
        "{who} walks in a circle {rot}",
        "{who} walks around in a full circle {rot}",
        "{who} is walking in a {rot} circle",
    ],
    "turn_around": [
        "{who} turns around to the {side}",
        "{who} turns around on the spot, to the {side}",
        "{who} does a half turn to the {side}",
    ],
    "step_over": [
        "{who} steps over an obstacle",
        "{who} walks forward lifting the knees high to step over something",
        "{who} carefully steps over something on the ground",
    ],
    "raise_arm": ["{who} raises {arm}{spd}", "{who} lifts {arm} up{spd}", "{who} puts {arm} up in the air"],
    "wave": ["{who} waves with {arm}{cnt}", "{who} waves {arm}{cnt}", "{who} raises {arm} and waves{cnt}"],
    "punch": [
        "{who} punches with {arm}{cnt}",
        "{who} throws a punch with {arm}{cnt}",
        "{who} boxes, punching with {arm}{cnt}",
    ],
    "reach": [
        "{who} reaches out with {arm}",
        "{who} reaches forward with {arm}",
        "{who} stretches {arm} out to grab something",
    ],
    "clap": ["{who} claps{cnt}", "{who} claps the hands{cnt}", "{who} applauds, clapping{cnt}"],
    "throw": [
        "{who} throws something with {arm}",
        "{who} throws a ball overhand with {arm}",
        "{who} winds up and throws with {arm}",
    ],
    "kick": [
        "{who} kicks{amp} with {leg}{cnt}",
        "{who} does a{amp_adj} kick with {leg}{cnt}",
        "{who} kicks {leg}{amp} forward{cnt}",
    ],
    "lunge": [
        "{who} lunges forward with {leg}",
        "{who} steps into a lunge with {leg}",
        "{who} does a forward lunge on {leg}",
    ],
    "squat": ["{who} squats down{cnt}", "{who} does a squat{cnt}", "{who} bends the knees and squats{cnt}"],
    "hop": ["{who} hops on {leg}{cnt}", "{who} hops on one leg, {leg}{cnt}", "{who} balances and hops on {leg}{cnt}"],
    "kneel": [
        "{who} kneels down on the {knee} knee and stands back up",
        "{who} goes down on the {knee} knee and gets up again",
        "{who} kneels briefly on the {knee} knee",
    ],
    "jump_up": [
        "{who} jumps{amp} in place{cnt}",
        "{who} jumps up{amp}{cnt}",
        "{who} does a{amp_adj} vertical jump{cnt}",
    ],
    "jump_forward": ["{who} jumps forward{cnt}", "{who} leaps forward{cnt}", "{who} does a long jump forward{cnt}"],
    "jumping_jacks": [
        "{who} does jumping jacks{cnt}",
        "{who} does {num} jumping jacks",
        "{who} performs jumping jacks{cnt}",
    ],
    "sit_down": ["{who} sits down", "{who} sits down on a chair", "{who} takes a seat"],
    "stand_up": ["{who} stands up", "{who} gets up from a chair", "{who} rises from a seated position"],
    "lie_down": [
        "{who} lies down on the floor",
        "{who} sits down on the ground and lies back",
        "{who} lies down on the back",
    ],
    "get_up": [
        "{who} gets up from the floor",
        "{who} stands up from lying on the ground",
        "{who} rises from lying down",
    ],
    "bow": ["{who} bows", "{who} bows politely", "{who} bends forward in a bow"],
    "stretch": [
        "{who} stretches the arms overhead and leans side to side",
        "{who} stretches, arms up, bending left and right",
        "{who} does a standing side stretch with both arms up",
    ],
}


def _pick(rng: np.random.Generator, options: list[str]) -> str:
    return options[int(rng.integers(len(options)))]


def captions_for(spec: Spec, rng: np.random.Generator, n: int = 3) -> list[str]:
    """n distinct captions (fewer if the templates run out) for one action."""
    templates = TEMPLATES[spec.kind] if spec.kind in TEMPLATES else REGISTERED[spec.kind].captions
    order = rng.permutation(len(templates))
    out: list[str] = []
    for i in range(max(n, 1) * 3):
        tpl = templates[order[i % len(templates)]]
        side = spec.side or ("left" if spec.direction in ("left", "ccw") else "right")
        spd = _pick(rng, SPEED_ADV[spec.speed])
        cnt = spec.count
        high = spec.amplitude == "high"
        text = tpl.format(
            who=_pick(rng, WHO),
            dir=_pick(rng, DIR_PHRASE.get(spec.direction or "forward", ["forward"])),
            spd=f" {spd}" if spd else "",
            side=side,
            angle=spec.angle or 90,
            rot="clockwise" if spec.direction == "cw" else "counterclockwise",
            arm=_pick(rng, ARM.get(spec.side or "both", ARM["both"])),
            leg=_pick(rng, LEG.get(spec.side or "left", LEG["left"])),
            knee=spec.side or "left",
            cnt=f" {COUNT[cnt]}" if cnt else "",
            num=NUM.get(cnt or 3, "a few"),
            amp=" high" if high else "",
            amp_adj=" high" if high else "",
        )
        text = " ".join(text.split())
        if text not in out:
            out.append(text)
        if len(out) == n:
            break
    return out
