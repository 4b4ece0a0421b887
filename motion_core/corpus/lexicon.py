"""The prompt reader's vocabulary: the words that name each corpus action kind, the actions
people ask for that the corpus does not have, and the little words that join clauses.

Adding a kind to the corpus is one entry in :data:`KINDS` (its verbs, its phrases and a phrase
for people); ``tests/test_prompt_reader.py`` checks that every kind of
``corpus.actions.CATALOGUE`` and of ``prompt_guide.MOCAP_ONLY`` has one. Whether a kind takes a
side, a direction or a count is not written here: it is read from the catalogue's variants.

Patterns are regular expressions over a *normalised* clause (:func:`normalise`: lower case,
hyphens as spaces, number words as digits, "counter clockwise" / "anticlockwise" as ``ccw`` and
"clockwise" as ``cw``), matched on word boundaries. Entries are tried in order, so a more specific
phrase goes before a general one ("jumping jacks" before "jump", "turns around" before "turns").
:data:`STRONG` is tried before :data:`KINDS`: its phrases are specific ("picks up", "push ups",
"jumps to the left") and would otherwise be read as a known kind's verb ("picks", "jumps").
:data:`WEAK` is tried after them. Every word added here is a synonym of a kind or the name of
an action the corpus lacks; the joining words (``SEQUENCE_WORDS``, ``TOGETHER_WORDS``,
``CAUSE_WORDS``, ``LIGHT_VERBS``, ``TO_COMPLEMENT``, ``CONTINUE``, ``RECOVER``) are closed
classes of English, not phrases of any caption set.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field


def inflect(b: str) -> tuple[str, str, str, str]:
    """A base's regular forms: (base, third person, past, -ing): walk -> walks, walked, walking;
    wave -> waves, waved, waving; hop -> hops, hopped, hopping (overstep -> overstepping); punch ->
    punches; carry -> carries."""
    if b.endswith("e") and not b.endswith("ee"):
        return b, b + "s", b + "d", b[:-1] + "ing"
    if b.endswith(("s", "sh", "ch", "x", "z")) or b in ("go", "do"):
        return b, b + "es", b + "ed", b + "ing"
    if b.endswith("y") and b[-2:-1] not in "aeiou":
        return b, b[:-1] + "ies", b[:-1] + "ied", b + "ing"
    if len(b) <= 4 and b[0] not in "aeiou" and re.fullmatch(r"[a-z]*[^aeiou][aeiou][bdgklmnprt]", b):
        return b, b + "s", b + b[-1] + "ed", b + b[-1] + "ing"
    if (m := re.fullmatch(r"(over|side|out|under|back)([a-z]{3,4})", b)) and inflect(m.group(2))[3].endswith(
        b[-1] * 2 + "ing"
    ):
        return b, b + "s", b + b[-1] + "ed", b + b[-1] + "ing"  # a compound doubles as its verb: overstepping
    return b, b + "s", b + "ed", b + "ing"


def forms(*bases: str) -> str:
    """A regex alternation of the bases' regular verb forms (:func:`inflect`): walk ->
    walk|walks|walked|walking. Irregular forms are listed as bases of their own."""
    out: list[str] = []
    for b in bases:
        if " " in b or not b.isalpha():
            out.append(b)
        else:
            out += inflect(b)
    return "(?:" + "|".join(sorted(set(out), key=len, reverse=True)) + ")"


@dataclass(frozen=True)
class KindWords:
    """How people name one corpus kind.

    verbs: base forms whose any form in a clause means this kind (inflected by :func:`forms`).
    phrases: further regexes (nouns, set phrases) that mean it.
    title: the kind for people, imperative, with ``{side}`` / ``{direction}`` slots filled where
    known ("wave the {side} hand"); the slot's words vanish when it is unknown.
    """

    kind: str
    title: str
    verbs: tuple[str, ...] = ()
    phrases: tuple[str, ...] = ()
    pattern: re.Pattern = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        alts = list(self.phrases) + ([forms(*self.verbs)] if self.verbs else [])
        object.__setattr__(self, "pattern", re.compile(r"\b(?:" + "|".join(alts) + r")\b"))


def _k(kind: str, title: str, verbs: tuple[str, ...] = (), phrases: tuple[str, ...] = ()) -> KindWords:
    return KindWords(kind, title, verbs, phrases)


_LIMB = r"(?:arms?|hands?|fists?)"
_LEG = r"(?:legs?|foot|feet)"
_ANY = r"(?:\w+ ){0,3}"  # up to three words in between

# The corpus's kinds, most specific first. Every CATALOGUE kind and every motion-capture-only
# kind has exactly one entry.
KINDS: tuple[KindWords, ...] = (
    _k("jumping_jacks", "do jumping jacks", phrases=(r"jumping jacks?", r"star jumps?", r"jumping jack")),
    _k("mocap:bye", "wave goodbye", phrases=(r"good ?bye", r"bye bye", r"byebye", r"says? bye", r"farewell")),
    _k(
        "mocap:call",
        "beckon someone over",
        verbs=("beckon",),
        phrases=(
            rf"{forms('call', 'wave', 'signal', 'motion', 'gesture')} "
            r"(?:someone|somebody|him|her|them|people|a \w+|the \w+)? ?"
            r"(?:over|to come|closer)",
        ),
    ),
    _k(
        "mocap:guide",
        "point the way",
        verbs=("guide",),
        phrases=(rf"{forms('show')} {_ANY}(?:the way|direction)",),
    ),
    _k("mocap:respond", "answer with a gesture", verbs=("respond",), phrases=(r"answers? with",)),
    _k("mocap:slash", "slash with a sword", verbs=("slash",), phrases=(r"swords?", r"sabre", r"saber")),
    _k(
        "mocap:dance-long",
        "dance",
        verbs=("dance", "waltz", "tango", "boogie"),
        phrases=(
            r"cha ?cha(?: ?cha)?",
            r"ballet",
            r"salsa",
            r"disco",
            r"ballroom",
            r"foxtrot",
            r"samba",
            r"rumba",
            r"jive",
        ),
    ),
    _k(
        "get_up",
        "get up from the floor",
        phrases=(
            rf"{forms('get', 'stand', 'rise', 'got', 'stood', 'rose')} up (?:\w+ ){{0,2}}(?:lying|laying)",
            rf"{forms('get', 'stand', 'rise', 'come', 'got', 'stood', 'rose')} {_ANY}(?:up )?(?:from|off) "
            r"(?:the |a )?(?:floor|ground|lying|lying position|supine|prone|mat)",
        ),
    ),
    _k(
        "lie_down",
        "lie down on the floor",
        phrases=(
            rf"{forms('lie', 'lay', 'laying')} {_ANY}(?:down|on (?:the|his|her|their|its) (?:back|floor|ground|belly))",
            r"lies?|lying",
        ),
    ),
    _k(
        "stand_up",
        "stand up",
        phrases=(
            rf"{forms('stand', 'get', 'stood', 'got')} (?:back )?up",
            rf"{forms('rise', 'rose')} (?:up|from)",
            rf"{forms('get')} (?:back )?on (?:his|her|their|its|the) feet",
        ),
    ),
    _k(
        "sit_down",
        "sit down",
        verbs=("sit", "sat"),
        phrases=(
            r"takes? a seat",
            r"(?<!to the )(?<!to a )(?<!towards the )(?<!toward the )(?:chair|stool|bench|seat)",
        ),
    ),
    _k(
        "kneel",
        "kneel on the {side} knee",
        verbs=("kneel", "knelt"),
        phrases=(
            rf"{forms('go', 'goes', 'went', 'get', 'got')} (?:down )?(?:on|to|onto) {_ANY}knees?",
            r"on (?:one|a|his|her|the \w+) knee",
            r"knees? down",
        ),
    ),
    _k("lunge", "lunge forward with the {side} leg", verbs=("lunge",)),
    _k(
        "squat",
        "squat",
        verbs=("squat", "crouch", "squad"),
        phrases=(rf"{forms('bend')} (?:the |his |her |their |both )?knees", r"knee bends?"),
    ),
    _k(
        "jump_forward",
        "jump forward",
        phrases=(
            rf"{forms('jump', 'leap', 'leapt', 'bound', 'hop')} (?:\w+ ){{0,7}}(?:forwards?|ahead|to the front)",
            r"(?:long|broad|forward) jumps?",
            rf"{forms('jump', 'leap', 'leapt', 'hurdle', 'vault')} (?:\w+ ){{0,3}}over",
            forms("hurdle", "vault"),
        ),
    ),
    _k(
        "hop",
        "hop on the {side} leg",
        verbs=("hop",),
        phrases=(rf"{forms('jump')} on (?:one|1|a single|the left|the right|his \w+|her \w+|its \w+) (?:leg|foot)",),
    ),
    _k("jump_up", "jump in place", verbs=("jump", "leap", "leapt")),
    _k(
        "step_over",
        "step over an obstacle",
        verbs=("overstep",),
        phrases=(
            rf"{forms('step', 'walk', 'go', 'goes', 'climb', 'move')} {_ANY}over",
            r"high knees",
        ),
    ),
    _k(
        "circle",
        "walk in a circle {direction}",
        phrases=(
            r"(?<!quarter )(?<!half )(?<!quarter of a )(?<!half of a )(?<!degrees of a )(?<!degree of a )"
            r"circl(?:e|es|ed|ing)",
            r"circular",
            r"circuits?",
            r"ellipses?|elliptic\w*|ovals?",
            rf"{forms('walk', 'go', 'goes', 'went', 'move', 'stroll', 'march')} (?:(?!quarter|half|90|180)\w+ ){{0,3}}"
            r"(?:ccw|cw)\b",
            r"(?:full|whole|complete) (?:round|loop|turn)",
            r"loops?",
            r"in an? (?:\w+ )?(?:square|rectangle|quadrangle)",  # a closed path (PROTOCOL.md)
        ),
    ),
    _k(
        "turn_around",
        "turn around to the {side}",
        phrases=(
            rf"{forms('turn', 'spin', 'spun', 'rotate', 'swivel', 'pivot', 'whirl', 'twirl')} "
            rf"{_ANY}(?:around|round|about|back)",
            r"pirouettes?",
            rf"{forms('turn', 'spin', 'spun', 'rotate', 'pivot', 'swivel')} {_ANY}(?:180|half)",
            rf"{forms('turn', 'spin', 'spun', 'pivot')} on (?:his|her|its|their|the|one) heels?",
            rf"{forms('turn', 'spin', 'spun', 'pivot', 'rotate', 'twirl')} (?:\w+ ){{0,3}}"
            r"(?:on (?:his|her|its|their|the|one|a|1) (?:\w+ )?(?:foot|feet|leg|toes?|spot)|in place)",
            r"half (?:turn|rotation)",
            r"about (?:face|turn)",
            r"u turn",
            r"180 degrees? (?:turn|rotation)",
        ),
    ),
    _k(
        "turn",
        "walk and turn {side}",
        verbs=("turn", "curve", "rotate", "spin", "spun", "veer", "swerve"),
        phrases=(
            r"curves?",
            r"corners?",
            r"(?:90|quarter) degrees?",
            r"(?:quarter|half) (?:of a )?(?:turn|circle|round)",
            r"(?:left|right) bend",
            r"bends? to the (?:left|right)",
            rf"{forms('change', 'reverse')} (?:\w+ )?(?:(?:the|his|her|its|their) )?(?:walking )?"
            r"(?:directions?|course)",
            r"changes? (?:of|in) (?:the )?(?:walking )?directions?",
        ),
    ),
    _k(
        "walk_backward",
        "walk backwards",
        phrases=(
            rf"{forms('walk', 'step', 'move', 'go', 'goes', 'went', 'run', 'ran', 'jog', 'stroll', 'shuffle', 'head')} "
            r"(?:\w+ ){0,5}backwards?",
            rf"{forms('take', 'took', 'make', 'made', 'do', 'does', 'did', 'perform')} "
            r"(?:\w+ ){0,5}steps? backwards?",
            r"backwards? (?:\w+ )?(?:walk\w*|steps?|gait|locomotion)",
            r"steps? backwards?",
            r"steps? (?:\w+ ){0,2}to the (?:rear|back)",
            r"in reverse",
            r"reverse walk(?:ing)?",
            rf"{forms('back')} (?:up|away|off)",
            rf"{forms('step')} back",
            r"steps? (?:\w+ ){0,2}back\b",
            r"rearwards?",
        ),
    ),
    _k(
        "sidestep",
        "step sideways to the {side}",
        verbs=("sidestep", "side step", "shuffle", "sidle"),
        phrases=(
            r"side ?steps?",
            rf"{forms('step', 'walk', 'move', 'go', 'goes', 'shift', 'slide')} (?:\w+ ){{0,2}}"
            r"(?:sideways|sidewards?|to (?:the|his|her|its|their|one) sides?|laterally|side to side)",
            r"crab ?wise|crab ?like|like a crab",
            r"(?:a |one |1 |small |big )?steps? (?:\w+ )?to (?:the |his |her |its )?(?:left|right)",
            rf"{forms('step')} (?:\w+ ){{0,4}}to (?:the |his |her |its )?(?:left|right)",
            r"lateral (?:moves?|steps?|movements?)",
            r"cross(?:es|ing)? (?:over )?steps?",
        ),
    ),
    _k("jog", "jog {direction}", verbs=("jog", "trot"), phrases=(r"runs? (?:at an )?easy pace", r"joggs?")),
    _k("run", "run {direction}", verbs=("run", "ran", "sprint", "dash", "race"), phrases=(r"running",)),
    _k(
        "walk",
        "walk {direction}",
        verbs=(
            "walk",
            "stroll",
            "march",
            "stride",
            "strode",
            "pace",
            "wander",
            "trudge",
            "saunter",
            "amble",
            "hurry",
            "return",
        ),
        phrases=(
            rf"{forms('go', 'goes', 'went', 'move', 'head', 'proceed', 'travel', 'advance', 'return')} "
            r"(?!(?:his|her|its|their|the|both|one|a) (?:\w+ )?(?:hand|arm|leg|foot|feet|head|finger)s?\b)"
            r"(?:back\b|away\b|(?:(?!\w*(?:hand|arm|leg|foot|feet|head|finger|body|hip)s?\b)\w+ ){0,4}"
            r"(?:forwards?|ahead|straight|to the (?:left|right)|left|right|diagonal\w*|"
            r"towards?|along|"
            r"to (?:the|a|an|his|her|its|their)))",
            r"steps? forwards?",
            rf"{forms('get', 'got', 'come', 'came', 'find', 'found')} (?:its |his |her |their )?(?:way )?back "
            r"(?:to|on|onto|into|in)",
            r"(?:takes?|taking|makes?|making|does|doing|performs?|performing) (?:\d+|a few|few|some|several|"
            r"a couple of|a number of|many|multiple|small|big|large|short|long|slow|quick|a|an|one) "
            r"(?:(?!recovery)\w+ ){0,3}steps?",
            r"steps",
            r"walks?",
            r"gait",
        ),
    ),
    _k(
        "raise_arm",
        "raise the {side} arm",
        phrases=(
            rf"{forms('raise', 'lift', 'put', 'hold', 'extend', 'throw')} {_ANY}{_LIMB} "
            r"(?:up|upwards?|high|above|over|in the air|into the air|overhead)",
            rf"{forms('raise', 'lift')} {_ANY}{_LIMB}",
            rf"{forms('move', 'bring', 'brought', 'swing', 'swung')} {_ANY}{_LIMB} "
            r"(?:up|upwards?|above|overhead|over (?:the|his|her|its|their) head|into the air|in the air)",
            rf"{forms('hold', 'held', 'put', 'stick', 'throw', 'threw')} up {_ANY}{_LIMB}",
            rf"{forms('stretch', 'extend', 'spread', 'hold', 'held')} {_ANY}{_LIMB} "
            r"(?:out|outwards?|wide|sideways|to the sides?|apart|horizontal\w*)",
            # arms spread, opened wide or stretched out are raised, hands or arms stretched
            # forward too (PROTOCOL.md: "stretch out" names arms stretched out; a bare "stretches
            # the arms" is the standing stretch)
            rf"{forms('spread', 'open')} (?:wide |up )?{_ANY}arms\b",
            # "rises his right arm": "rise" takes no object, so with a limb after it is "raise"
            rf"(?:rise|rises|rising|rose) (?:his|her|their|its|the|both|one|a) (?:\w+ )?{_LIMB}",
            # hands held before the chest or at a height are raised (not a thing held in them)
            rf"{forms('hold', 'held', 'keep', 'kept')} (?:up )?(?:his|her|their|its|the|both) (?:\w+ )?(?:hands|arms) "
            r"(?:\w+ )?(?:in front of|on the height|at the height|to the height|"
            r"at (?:shoulder|chest) (?:height|level))",
            rf"{forms('stretch', 'extend')} (?:out )?{_ANY}arms? (?:\w+ )?(?:forwards?|in front)",
            rf"{forms('stretch')} out {_ANY}arms\b",
            rf"{_LIMB} (?:\w+ )?(?:stretched|extended|spread|outstretched|raised)",
            r"t pose",
            rf"{forms('raise', 'lift')} (?:up|high)",
            rf"{_LIMB} (?:up|in the air|above (?:the|his|her) head)",
            rf"(?:with )?(?:his |her |their |its |both |the )?{_LIMB} (?:held |stretched |spread )?out\b",
            r"raises?|raising",
        ),
    ),
    _k("wave", "wave the {side} hand", verbs=("wave", "greet"), phrases=(r"waving",)),
    _k(
        "punch",
        "punch with the {side} arm",
        verbs=("punch", "jab", "uppercut"),
        # "boxing", "he boxes", not "a box"
        phrases=(
            r"punch(?:es)?",
            r"boxing",
            r"boxed",
            r"(?<!a )(?<!the )boxes\b(?! of)",
            r"throws? (?:a |some )?(?:punch|jab|hook)",
            r"left hook|right hook",
            # hitting with the hand or fist is a punch; with no hand named it may be a kick
            rf"{forms('hit', 'strike', 'struck')} (?:\w+ ){{0,5}}with (?:his |her |its |their |the |a |one )?"
            r"(?:left |right )?(?:hand|fist)s?\b",
        ),
    ),
    _k("kick", "kick with the {side} leg", verbs=("kick",), phrases=(r"kicks?", r"side ?kicks?")),
    _k(
        "reach",
        "reach forward with the {side} hand",
        verbs=("reach", "grab", "grasp"),
        phrases=(rf"{forms('stick')} {_ANY}{_LIMB} (?:out|forward)", r"reaches"),
    ),
    _k("clap", "clap the hands", verbs=("clap", "applaud"), phrases=(r"applause",)),
    _k("throw", "throw something with the {side} arm", verbs=("throw", "threw", "thrown", "toss", "pitch", "hurl")),
    _k(
        "bow",
        "bow",
        verbs=("bow",),
        phrases=(
            r"bows?",
            rf"{forms('bend', 'lean', 'tilt')} {_ANY}(?:forward|forwards) (?:and back|from the waist)",
            # bending or leaning the body forward, with no reach or pick-up named, is a bow
            # (PROTOCOL.md labels "bends forward", "leans forward" and "bends her upper body" so)
            rf"{forms('bend', 'lean')} (?:(?:a bit|a little|a little bit|slightly|deeply|far) )?"
            r"(?:(?:his|her|its|their|the) (?:upper )?(?:body|torso|trunk) )?(?:forwards?|over forwards?)\b",
            rf"{forms('bend')} (?:his|her|its|their|the) upper body\b(?! (?:to|sideways|back|left|right))",
        ),
    ),
    _k(
        "stretch",
        "stretch",
        verbs=("stretch",),
        phrases=(r"warm(?:s|ing)? up", r"stretches", rf"{forms('lean', 'bend', 'sway')} (?:from )?side to side"),
    ),
)

# Actions people ask for that the corpus does not have, each with its name for people:
# (name, patterns). STRONG is tried before KINDS (its phrases are specific: "picks up", "push
# ups", "jumps to the left"), WEAK after them (broad verbs such as "holds" or "looks", which in a
# clause with a known kind are its detail). A clause with any other verb of bodily motion
# (MOTION_VERBS) is unknown too, named by its own words.
_OBJ = r"(?:box|object|thing|something|bag|bottle|cup|glass|ball|weight|item|crate|case|basket|book|bucket|load|it)"
STRONG: tuple[tuple[str, tuple[str, ...]], ...] = (
    # gestures to the body that the grown corpus stages (AS_KIND): before "touch", "put down", "hold"
    ("shrug", (forms("shrug"),)),
    (
        "arm curls",
        (
            r"(?:biceps?|arm|dumbbell|hammer|barbell) curls?",
            rf"{forms('curl')} (?:\w+ ){{0,3}}(?:arms?|biceps?|dumbbells?|weights?|forearms?)\b",
        ),
    ),
    ("scratch head", (rf"{forms('scratch', 'rub')} (?:\w+ ){{0,4}}(?:head|hair|scalp)\b",)),
    (
        "touch face",
        (
            rf"{forms('touch', 'rub', 'cover', 'pat', 'tap', 'stroke')} (?:\w+ ){{0,3}}"
            r"(?:face|cheeks?|chin|forehead|nose)\b",
        ),
    ),
    ("touch toes", (rf"{forms('touch', 'reach', 'tap', 'grab')} (?:\w+ ){{0,3}}toes\b",)),
    (
        "clasp hands",
        (
            rf"{forms('clasp', 'fold', 'join', 'press', 'put')} (?:\w+ ){{0,3}}hands together",
            forms("clasp", "pray"),
            r"prayer",
        ),
    ),
    ("fold arms", (rf"{forms('cross', 'fold')} (?:\w+ ){{0,3}}arms\b",)),
    (
        "hands on hips",
        (
            rf"{forms('put', 'place', 'rest', 'set', 'plant')} (?:\w+ ){{0,3}}hands? (?:\w+ ){{0,2}}(?:on|onto) "
            r"(?:\w+ ){0,2}hips?\b",
        ),
    ),
    ("push-ups", (r"push ?ups?", r"press ?ups?")),
    ("sit-ups", (r"sit ?ups?", r"crunch(?:es)?")),
    ("pull-ups", (r"pull ?ups?", r"chin ?ups?")),
    ("burpees", (r"burpees?",)),
    (
        "turn 360 degrees",
        (
            rf"{forms('turn', 'spin', 'spun', 'rotate', 'pivot', 'twirl')} (?:\w+ ){{0,3}}360",
            r"(?:full|whole|complete|360 degrees?|360) (?:turn|spin|rotation|pirouette|revolution)s?",
        ),
    ),
    ("stretch legs", (rf"{forms('stretch')} (?:\w+ ){{0,3}}(?:legs?|hamstrings?|calf|calves|thighs?)",)),
    (
        "sit down on the floor",
        (rf"{forms('sit', 'sat')} (?:down )?(?:on|onto|to) (?:the |a )?(?:floor|ground|mat)",),
    ),
    ("jump rope", (rf"{forms('jump', 'skip')} (?:a |the )?rope", r"skipping rope", r"jump ?rope")),
    ("cartwheel", (r"cart ?wheels?",)),
    # a path in the shape of an eight; "lying" here is the eight's, not the body's
    ("walk in a figure eight", (r"(?:figure|figures|lying|number|shape of an?) (?:of )?(?:an? )?8\b", r"eights?\b")),
    ("headstand", (r"head ?stands?",)),
    ("handstand", (r"hand ?stands?", r"hand ?springs?", rf"{forms('walk', 'stand')} on (?:his |her |the |its )?hands")),
    ("backflip", (r"(?:back|front|forward|backward) ?flips?", r"somersaults?", r"saltos?", forms("flip"))),
    ("turn a wheel", (r"(?:steering )?wheels?",)),
    (
        "climb stairs",
        (
            r"stair(?:s|case|way)?",
            r"upstairs",
            r"downstairs",
            r"steps? (?:up|down) (?:a |the )?steps",
            # "walks down steps", "goes up the steps": steps as the thing climbed, not a count
            rf"{forms('walk', 'go', 'goes', 'went', 'climb', 'run', 'move', 'come', 'came')} (?:up|down) "
            r"(?:a few |some |the |several |\d+ )?steps\b",
        ),
    ),
    (
        "step up onto a step",
        (
            rf"{forms('step', 'climb', 'get', 'go', 'goes', 'walk')} (?:up )?(?:onto|on to|on top of|up on|on) "
            r"(?:a |the |an )?"
            r"(?:\w+ )?(?:step|platform|box|stool|chair|bench|stage|block|podium|table)",
        ),
    ),
    (
        "step down from a platform",
        (
            rf"{forms('step', 'get', 'go', 'goes', 'climb', 'walk')} (?:down|off) (?:from |of )?(?:a |the |an )?"
            r"(?:\w+ )?(?:step|platform|box|stool|chair|bench|stage|block|podium|table)",
        ),
    ),
    ("jump down", (rf"{forms('jump', 'leap', 'leapt', 'hop')} (?:down|off)",)),
    (
        "jump sideways",
        (
            rf"{forms('jump', 'leap', 'leapt', 'hop')} (?:\w+ ){{0,3}}"
            r"(?:to the (?:left|right)|sideways|sidewards?|to the side|"
            r"(?:left|right) side|laterally)",
            r"side ?jumps?",
            # a way before the noun says the same as after the verb: "a right jump" is a jump to the right
            r"(?:a|one|another|the) (?:\w+ )?(?:left|right|sideways|lateral) (?:jumps?|leaps?|hops?)\b",
        ),
    ),
    (
        "jump backward",
        (
            rf"{forms('jump', 'leap', 'leapt', 'hop')} (?:\w+ ){{0,3}}(?:backwards?|back)\b",
            r"(?:a|one|another|the) (?:\w+ )?backwards? (?:jumps?|leaps?|hops?)\b",
        ),
    ),
    ("climb", (forms("climb", "scale"), r"ladder", r"wall bars?")),
    ("run in a circle", (rf"{forms('run', 'ran', 'jog', 'sprint')} (?:\w+ ){{0,4}}(?:circles?|circular|ccw|cw)\b",)),
    (
        "lift an object overhead",
        (
            rf"{forms('lift', 'raise', 'hold', 'held', 'hoist')} (?:up )?(?:a |an |the |some )?(?:\w+ )?{_OBJ} "
            r"(?:\w+ ){0,2}(?:overhead|over (?:his|her|their|its|the) head|above (?:his|her|their|its|the) head)",
        ),
    ),
    (
        "pick up",
        (
            rf"{forms('pick')} (?:\w+ ){{0,3}}up",
            rf"{forms('lift', 'raise', 'grab', 'take', 'took', 'fetch', 'collect', 'retrieve')} "
            r"(?:up )?(?:a |an |the |some )?"
            rf"(?:\w+ )?{_OBJ}\b",
            rf"{forms('take', 'took', 'grab')} (?:\w+ ){{0,3}}(?:from|off) (?:the |a )?(?:floor|ground|table|shelf)",
        ),
    ),
    (
        "put down",
        (
            rf"{forms('put', 'place', 'set', 'drop', 'deposit', 'lower')} (?:\w+ ){{0,3}}"
            r"(?:down|on (?:the|a) (?:floor|ground|table|shelf))",
            rf"{forms('put', 'place', 'set', 'drop', 'deposit')} (?:it|them|something|the \w+|a \w+|an \w+)",
        ),
    ),
    (
        "pass object between hands",
        (
            rf"{forms('pass', 'hand', 'move', 'transfer', 'switch', 'swap')} (?:\w+ ){{0,3}}(?:to|into|between) "
            r"(?:the |his |her |its |their )?(?:other|left|right|both) hands?",
        ),
    ),
    ("carry", (forms("carry", "haul", "lug"),)),
    (
        "get down on all fours",
        (
            rf"{forms('get', 'got', 'go', 'goes', 'went', 'kneel', 'knelt', 'drop')} (?:down )?(?:\w+ ){{0,4}}"
            r"(?:on|onto|to) (?:all )?(?:fours?|4)\b",
            rf"{forms('get', 'got', 'go', 'goes', 'went', 'drop')} (?:down )?(?:on|onto|to) "
            r"(?:his |her |their |its |the )?(?:hands and knees|knees and hands)",
        ),
    ),
    ("crawl", (forms("crawl", "creep", "crept"), r"on (?:all )?fours|on all 4", r"(?:four|4) ?legged", r"quadruped")),
    ("swim", (forms("swim", "swam"), r"breast ?stroke", r"butterfly stroke", r"back ?stroke", r"front crawl")),
    (
        "stand up from kneeling",
        (
            rf"(?:up|{forms('rise', 'rose')}) (?:\w+ )?(?:from|off) (?:his |her |their |its |the |a |one |both )?"
            r"(?:knees?|kneeling)",
        ),
    ),
    (
        "rise to kneeling",
        (
            rf"(?:{forms('rise', 'rose', 'get', 'got', 'come', 'came')}) (?:up )?(?:to|into) (?:a )?kneeling",
            rf"(?:{forms('rise', 'rose', 'raise')}) (?:up )?(?:to|onto) (?:his |her |their |its |the |both )?knees",
        ),
    ),
    (
        "stumble",
        (
            forms("stumble", "trip", "stagger", "totter", "teeter", "slip", "fall", "fell", "collapse"),
            rf"{forms('lose', 'lost')} (?:\w+ ){{0,2}}balance",
            rf"{forms('tip', 'topple')} (?:over|forwards?|backwards?)",
        ),
    ),
    (
        "being pushed",
        (
            r"(?:is|are|gets?|getting|got|being|was|been|be) (?:\w+ )?"
            r"(?:pushed|shoved|hit|bumped|knocked|pulled|struck|"
            r"kicked|punched|attacked|tackled|nudged)",
            r"(?:pushed|shoved|knocked|bumped|nudged) (?:by|from|in|on|at|to|off|over|backwards|forwards?|aside)",
            rf"{forms('receive', 'get', 'take', 'experience', 'suffer')} (?:\w+ ){{0,3}}"
            r"(?:push|shove|hit|blow|bump|disturbance|punch|kick)",
            rf"{forms('recover', 'react')} (?:\w+ ){{0,2}}(?:from|to) (?:a |an |the |some )?(?:\w+ )?"
            r"(?:push|shove|hit|blow|bump|force|impact|nudge|disturbance)",
            r"pushed|shoved",
        ),
    ),
    (
        "walk around an obstacle",
        (
            rf"{forms('evade', 'avoid', 'circumvent', 'bypass', 'dodge')} (?:\w+ ){{0,2}}obstacles?",
            rf"{forms('walk', 'go', 'goes', 'went', 'move', 'step')} around (?:an |the |a |some )?(?:\w+ )?obstacles?",
        ),
    ),
    (
        "walk in a slalom",
        (
            r"slaloms?",
            r"zig ?zag\w*",
            r"weav(?:e|es|ing) (?:between|through|around)",
            r"(?:an? )?s[ -]?(?:shape|curve)\w*",
        ),
    ),
    ("walk up a slope", (r"(?:up|ascend\w*) (?:a |the )?(?:slope|hill|ramp|incline)", r"uphill")),
    ("walk down a slope", (r"(?:down|descend\w*) (?:a |the )?(?:slope|hill|ramp|incline)", r"downhill")),
    ("walk on a slope", (r"slopes?", r"hills?", r"ramps?", r"inclines?", r"slanted")),
    ("stomp", (forms("stomp", "stamp"),)),
    (
        "lift a foot",
        (
            rf"{forms('lift', 'raise')} (?:up )?(?:the |his |her |their |its |a |one )?(?:\w+ )?"
            r"(?:foot|leg|knee|feet|legs)",
        ),
    ),
    ("golf swing", (r"golf(?:er|ing)?", r"putts?")),
    ("swing a racket", (r"tennis", r"rackets?", r"racquets?", r"badminton", r"forehand", r"backhand", r"ping ?pong")),
    ("play baseball", (r"baseball", r"(?:swings?|swinging) (?:a |the )?bat", r"\bbat\b")),
    ("dribble a ball", (forms("dribble"), r"bounc\w* (?:a |the )?ball")),
    ("play basketball", (r"basketball", r"hoops?")),
    ("play football", (r"football", r"soccer", r"(?:heads?|heading) (?:a |the )?ball")),
    (
        "play an instrument",
        (
            r"guitars?",
            r"guitare",
            forms("strum"),
            r"violins?",
            r"violine",
            r"fiddles?",
            r"cello",
            r"drums?",
            r"drumming",
            r"drumsticks?",
            r"instruments?",
            r"piano",
            r"flute",
            r"trumpet",
            r"saxophone",
            r"clarinet",
            r"trombone",
        ),
    ),
    ("shoot a gun", (r"guns?", r"pistols?", r"rifles?", r"shotgun", rf"{forms('shoot', 'shot', 'aim')}")),
    ("juggle", (forms("juggle"),)),
    ("skip", (forms("skip"),)),
    ("limp", (forms("limp", "hobble"),)),
    ("swipe gesture", (forms("swipe"),)),
    (
        "wipe",
        (forms("wipe", "whipe", "clean", "scrub", "polish", "dust", "mop", "sweep", "swept", "vacuum", "wash", "rub"),),
    ),
    ("stir", (forms("stir", "whisk", "mix"),)),
    ("drink", (forms("drink", "drank", "sip"),)),
    ("eat", (forms("eat", "ate", "chew"),)),
    ("brush teeth", (r"teeth", r"toothbrush")),
    ("comb hair", (r"hair", forms("comb"))),
    ("hug", (forms("hug", "embrace", "cuddle"),)),
    (
        "shake hands",
        (rf"{forms('shake', 'shook')} (?:\w+ ){{0,3}}hands? with", rf"{forms('shake', 'shook')} hands\b", r"handshake"),
    ),
    ("dodge", (forms("dodge", "duck", "evade", "avoid"), r"evasive")),
    (
        "fight",
        (
            r"(?:fight|fights|fought|fighting)(?! (?:position|stance|pose|posture))",
            forms("spar", "wrestle"),
            r"karate",
            r"kung fu",
            r"martial arts?",
            r"taekwondo",
        ),
    ),
    ("catch", (forms("catch", "caught"),)),
    (
        "arm circles",
        (rf"{forms('rotate', 'circle', 'windmill', 'twirl')} (?:\w+ ){{0,3}}(?:arms?|hands?)", r"arm circles?"),
    ),
    ("point", (r"(?<!starting )(?<!the )(?<!a )(?<!to )(?<!end )(?:points?|pointing|pointed)\b(?! of)",)),
    ("salute", (forms("salute"),)),
    (
        "move the head",
        (
            rf"{forms('turn', 'rotate', 'twist', 'tilt', 'move', 'bob', 'shake', 'shook')} "
            r"(?:\w+ )?(?:his |her |their |its |the )head\b",
            forms("nod"),
        ),
    ),
    ("check a watch", (r"watch(?:es)? (?:\w+ ){0,2}(?:time|wrist)", r"(?:wrist ?)?watch\b", r"the time")),
    ("ride a bicycle", (r"bicycles?", r"bikes?", r"cycling", forms("pedal"))),
    ("drive", (forms("drive", "drove", "steer"),)),
    ("row", (r"rows?\b(?! of)", r"rowing", forms("paddle"), r"kayak\w*", r"canoe\w*", r"oars?")),
    ("skate or ski", (forms("skate", "ski", "snowboard", "surf"), r"skiing")),
    ("dig", (forms("dig", "dug", "shovel", "rake"),)),
    ("hammer", (forms("hammer", "saw", "chop", "hack"), r"axe")),
    ("write or type", (forms("write", "wrote", "type", "draw", "drew", "paint"), r"keyboard")),
    ("talk on the phone", (r"phones?", r"telephone")),
    ("do yoga", (r"yoga", r"tai chi")),
    (
        "open a door",
        (rf"{forms('open', 'close', 'shut', 'knock', 'unlock', 'lock')} (?:\w+ ){{0,3}}doors?", forms("knock")),
    ),
    # (arms opened wide are raised: raise_arm)
    ("open something", (forms("open", "unlock", "unscrew") + r"(?! (?:wide |up )?(?:\w+ )?arms\b)",)),
)
WEAK: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "recovery step",
        (
            forms("recover", "regain", "compensate", "counterbalance", "rebalance", "stabilize", "stabilise"),
            r"recovery",
        ),
    ),
    (
        "balance",
        (
            forms("balance"),
            rf"{forms('stand', 'stood')} on (?:one|1|a single|the left|the right|his \w+|her \w+|its \w+) (?:leg|foot)",
            r"one legged",
            r"flamingo",
        ),
    ),
    ("arm gestures", (forms("gesticulate", "gesture"), r"gestures?")),
    (
        "look down",
        (
            rf"{forms('look', 'glance', 'gaze', 'stare', 'peer')} (?:\w+ ){{0,2}}"
            r"(?:down\b|at (?:his|her|their|its|the) (?:own )?(?:feet|floor|ground|shoes))",
        ),
    ),
    ("look around", (forms("look", "glance", "peek", "peer", "search", "gaze", "stare", "watch"),)),
    ("lean backward", (rf"{forms('lean', 'tilt', 'arch')} (?:\w+ ){{0,3}}back(?:wards?)?\b",)),
    ("lean", (forms("lean", "tilt"),)),
    (
        "bend down",
        (rf"{forms('bend', 'bent', 'stoop')} (?:\w+ ){{0,3}}(?:down|over|to the ground|to the floor)", forms("stoop")),
    ),
    ("shake arms and legs", (forms("shake", "shook", "wiggle", "jiggle", "tremble", "shiver", "wriggle", "flap"),)),
    ("push", (forms("push", "shove", "press"),)),
    ("pull an object", (forms("pull", "drag", "tug", "yank"),)),
    ("touch the floor", (rf"{forms('touch', 'tap')} (?:\w+ ){{0,2}}(?:floor|ground|toes)\b",)),
    ("touch", (forms("touch", "tap", "pat", "scratch", "stroke", "poke", "slap", "hit", "strike", "struck"),)),
    ("hold", (forms("hold", "held", "grip", "clutch"),)),
    ("hang", (forms("hang", "hung", "dangle", "swing", "swung"),)),
    ("sneak", (forms("sneak", "snuck", "prowl"), r"stealth\w*")),
    ("imitate an animal", (r"chicken|monkey|gorilla|ape|frog|penguin|elephant|dog|cat|bird|zombie|robot|animal",)),
)
UNKNOWN: tuple[tuple[str, tuple[str, ...]], ...] = STRONG + WEAK


def _compile(entries: tuple[tuple[str, tuple[str, ...]], ...]) -> tuple[tuple[str, re.Pattern], ...]:
    return tuple((name, re.compile(r"\b(?:" + "|".join(pats) + r")\b")) for name, pats in entries)


STRONG_PATTERNS = _compile(STRONG)
WEAK_PATTERNS = _compile(WEAK)
UNKNOWN_PATTERNS = STRONG_PATTERNS + WEAK_PATTERNS

# Two clauses joined by "and" that the corpus's own captions use for one kind (its templates:
# "walks and turns left", "kneels down ... and stands back up", "raises the arm and waves").
# The first may be an unknown action's name ("sits down on the ground and lies back"). They are
# one kind only when the second names no body part of its own ("raises both arms and waves his
# hands" is two).
AND_PHRASINGS: dict[tuple[str, str], str] = {
    ("walk", "turn"): "turn",
    ("kneel", "stand_up"): "kneel",
    ("kneel", "get_up"): "kneel",
    ("sit_down", "lie_down"): "lie_down",
    ("raise_arm", "wave"): "wave",
    ("squat", "stand_up"): "squat",
    ("stretch", "stretch"): "stretch",
    ("sit down on the floor", "lie_down"): "lie_down",
}

# Unknown actions the reader's rules name rather than a pattern: a rest with no action around it,
# a turn during a jump, and a hand moved up and down by a verb that does not raise it.
RULE_NAMES = ("stand still", "turn in the air", "move hand up and down")

# The known kind nearest to an unknown action, for the warning's "(nearest: ...)"; an unknown
# without an entry gets the sentence encoder's nearest training caption instead.
NEAREST: dict[str, str] = {
    "walk in a figure eight": "circle",
    "pick up": "reach",
    "put down": "reach",
    "lift an object overhead": "raise_arm",
    "carry": "walk",
    "pass object between hands": "clap",
    "catch": "reach",
    "wipe": "reach",
    "stir": "reach",
    "swipe gesture": "wave",
    "crawl": "kneel",
    "get down on all fours": "kneel",
    "stand up from kneeling": "kneel",
    "rise to kneeling": "kneel",
    "push-ups": "lie_down",
    "sit-ups": "lie_down",
    "pull-ups": "raise_arm",
    "burpees": "squat",
    "stumble": "walk",
    "being pushed": "sidestep",
    "recovery step": "sidestep",
    "balance": "hop",
    "dodge": "sidestep",
    "climb stairs": "step_over",
    "step up onto a step": "step_over",
    "step down from a platform": "step_over",
    "climb": "step_over",
    "jump down": "jump_forward",
    "jump sideways": "jump_up",
    "jump backward": "jump_up",
    "turn in the air": "jump_up",
    "backflip": "jump_up",
    "cartwheel": "jump_up",
    "jump rope": "jump_up",
    "skip": "jog",
    "run in a circle": "circle",
    "walk up a slope": "walk",
    "walk down a slope": "walk",
    "walk on a slope": "walk",
    "walk around an obstacle": "turn",
    "walk in a slalom": "turn",
    "limp": "walk",
    "sneak": "walk",
    "stomp": "walk",
    "lift a foot": "kick",
    "golf swing": "throw",
    "swing a racket": "throw",
    "play baseball": "throw",
    "play basketball": "throw",
    "dribble a ball": "throw",
    "shoot a gun": "reach",
    "point": "mocap:guide",
    "salute": "raise_arm",
    "arm circles": "stretch",
    "lean": "stretch",
    "lean backward": "stretch",
    "bend down": "bow",
    "fight": "punch",
    "hug": "reach",
    "shake hands": "reach",
    "open a door": "reach",
    "open something": "reach",
    "touch": "reach",
    "hold": "raise_arm",
    "stand still": "bow",
    "swim": "stretch",
    "do yoga": "stretch",
    "turn 360 degrees": "turn_around",
    "stretch legs": "stretch",
    "sit down on the floor": "sit_down",
    "arm gestures": "mocap:respond",
    "move hand up and down": "wave",
    "touch the floor": "bow",
}

# The staged kinds (``corpus.kinds``, not yet in the models' ``CATALOGUE``) that an unknown
# action's name above stands for: (name, words pattern or None, kind). The first entry whose name
# is the clause's and whose pattern (if any) is found in its normalised words decides; kind None
# keeps it unknown (a 270-degree turn is no spin_jump). While the kind is staged the clause stays
# unknown and the warning names it; once the kind moves into ``CATALOGUE`` with retrained models
# the reader reads it as that kind, and the STRONG patterns, tried first, do not shadow it.
AS_KIND: tuple[tuple[str, str | None, str | None], ...] = (
    ("being pushed", None, "being_pushed"),
    ("stumble", None, "stumble"),
    ("dodge", None, "dodge"),
    ("wipe", None, "wipe"),
    ("stir", None, "stir"),
    ("drink", None, "drink"),
    ("pick up", None, "pick_up"),
    ("put down", None, "put_down"),
    ("carry", None, "carry"),
    ("crawl", None, "crawl"),
    ("push-ups", None, "push_up"),
    ("sit-ups", None, "sit_up"),
    ("stand up from kneeling", None, "stand_up_from_kneeling"),
    ("play an instrument", r"violin|fiddle", "play_violin"),
    ("play an instrument", r"guitar|gitar", "play_guitar"),
    ("golf swing", None, "golf_swing"),
    ("swing a racket", r"forehand", "tennis_forehand"),
    ("dribble a ball", None, "dribble"),
    ("fight", r"\bbox|jabs?\b", "boxing"),
    ("swim", r"breast|butterfly|back ?stroke|styles", None),
    ("swim", None, "swim"),
    ("turn in the air", r"\b270\b|pirouette", None),
    ("turn in the air", None, "spin_jump"),
    ("turn 360 degrees", None, "spin"),
    ("jump sideways", None, "jump_sideways"),
    ("jump backward", None, "jump_backward"),
    ("stomp", None, "stomp"),
    ("step up onto a step", None, "step_up_onto"),
    ("climb stairs", r"\bdown|descend", "walk_downstairs"),
    ("climb stairs", None, "walk_upstairs"),
    ("balance", r"one (?:foot|leg)", "stand_on_one_leg"),
    ("lift a foot", None, "stand_on_one_leg"),
    ("arm circles", None, "arm_circles"),
    ("look around", None, "look_around"),
    ("check a watch", None, "check_watch"),
    ("talk on the phone", None, "phone_call"),
    ("salute", None, "salute"),
    ("shrug", None, "shrug"),
    ("arm curls", None, "bicep_curls"),
    ("scratch head", None, "scratch_head"),
    ("touch face", None, "touch_face"),
    ("touch toes", None, "touch_toes"),
    ("clasp hands", None, "clasp_hands"),
    ("fold arms", None, "cross_arms"),
    ("hands on hips", None, "hands_on_hips"),
)

# Staged kinds that are a finer way of a kind the models know: (known kind, words pattern, staged
# kind). While the staged kind is not in ``CATALOGUE`` the clause stays the known kind (the
# models can do that much); once it is, a clause of the known kind whose normalised words match
# is read as the finer one ("kneels down on both knees" as kneel_down, not the kneel on one knee).
FINER_KIND: tuple[tuple[str, str, str], ...] = (
    ("kneel", r"\b(?:both|two|2) knees\b", "kneel_down"),
    ("walk", r"\bmarch\w* (?:\w+ ){0,2}(?:in place|on the (?:same )?spot|in one place)\b", "march_in_place"),
    (
        "walk",
        r"\b(?:(?:on|along|following) an? (?:straight |thin |narrow )?line|heel to toe|tight ?rope|balance beam)\b",
        "walk_a_line",
    ),
)

# Verbs of bodily motion: a clause with one of these that names neither a kind nor a known
# unknown is an action the models do not know. (Verbs in KINDS and UNKNOWN count as well.)
MOTION_VERBS = tuple(
    """
    act bounce break bump bend bent cross drop exercise flap float fly flew glide hit hover imitate
    kneel lift lower mimic move nod perform play pose practice practise pretend rock rotate shift shoot
    slide slid spread stamp step strike swing swung sway swirl tap throw tilt twist wiggle wave show
    demonstrate simulate fidget stomp turn go goes went come came walk run jump kick punch hop sit stand
    lie get put take took make made do does did reach raise clap bow stretch dance squat lunge crouch
    spin leap roll crawl climb carry pick push pull fall trip stumble hang hold grab touch lean look
    point wipe stir drink eat swim skip limp dodge duck catch shake balance recover support land prepare
    receive return approach avoid pass enter leave follow lead chase flee hide sneak rise lay place set
    open close knock tie fold pour fill brush comb wash wobble twirl whirl tumble wriggle stagger gallop
    prance skate slip flail beat bang smash flutter shrug flex cast toss pivot jiggle sprawl slouch
    hunch squirm writhe thrash wrestle grapple nudge change reverse
    """.split()
)
# Verbs of starting, going on and trying: both auxiliaries and verbs that take "to" + a verb.
ASPECT_VERBS = (
    "start",
    "begin",
    "began",
    "begun",
    "continue",
    "proceed",
    "keep",
    "kept",
    "try",
    "tried",
    "seem",
    "appear",
    "attempt",
    "want",
    "need",
    "decide",
    "manage",
)
# Verbs that say when or how rather than what (a clause of these alone joins its neighbour).
AUXILIARY = (
    *ASPECT_VERBS,
    "go on",
    "repeat",
    "end",
    "finish",
    "is",
    "are",
    "was",
    "were",
    "be",
    "been",
    "being",
    "has",
    "have",
    "had",
    "can",
    "could",
    "will",
    "would",
    "may",
    "might",
    "should",
)
# "stops", "stands still": the end of an action, not one of its own (every clip has rest at its
# ends). Alone in a prompt it is an unknown ("stand still").
REST = (
    rf"{forms('stop', 'halt', 'pause', 'wait', 'rest', 'stay', 'remain', 'freeze', 'froze', 'idle')}",
    rf"{forms('stand', 'stood')}(?: \w+)? (?:still|there|up straight|upright|in place|on the spot|around|idle|quietly)",
    rf"{forms('stand', 'stood')}$",
    r"standing",
    r"stands",
    # coming to a halt, slowing down or closing the feet ends the movement before; it is no action
    rf"{forms('come', 'came')} to (?:a )?(?:rest|halt|stop|standstill|stand)",
    rf"{forms('get', 'got', 'become', 'became', 'grow', 'grew')} (?:\w+ )?slower",
    rf"{forms('slow')} down",
    r"slowing",
    rf"{forms('close', 'bring', 'brought', 'put', 'place')} (?:his|her|its|their|the|both) (?:feet|legs|heels)"
    r"(?: together)?",
)
REST_PATTERN = re.compile(r"\b(?:" + "|".join(REST) + r")\b")

# Words that join clauses. Sequence words and fillers never become clauses of their own.
SEQUENCE_WORDS = (
    "then",
    "afterwards",
    "afterward",
    "after that",
    "after this",
    "after which",
    "after wards",
    "next",
    "finally",
    "later",
    "subsequently",
    "eventually",
    "lastly",
    "at last",
    "at the end",
    "in the end",
    "followed by",
    "and then",
    "thereafter",
    "initially",
    "and",
)
TOGETHER_WORDS = (
    "while",
    "whilst",
    "meanwhile",
    "in the meantime",
    "at the same time",
    "simultaneously",
    "during that",
    "during this",
    "during which",
    "as he",
    "as she",
    "as they",
)
# Words that give a cause: what follows them happened first ("steps aside because of a push").
CAUSE_WORDS = (
    "since",
    "due to",
    "because of",
    "because",
    "owing to",
    "as a result of",
    "caused by",
    "thanks to",
    "in response to",
    "in reaction to",
    "as a reaction to",
    "as a response to",
)
# Verbs whose object names the action ("takes three steps", "performs two kicks", "does a turn"):
# the word after them that looks like a verb is their object.
LIGHT_VERBS = (
    "take",
    "took",
    "taken",
    "make",
    "made",
    "do",
    "does",
    "did",
    "done",
    "perform",
    "execute",
    "give",
    "gave",
    "have",
    "has",
    "had",
    "show",
    "complete",
    "practice",
    "practise",
    "repeat",
    "start",
    "begin",
    "finish",
)
# Words after which "to" and a verb is their complement ("starts to walk", "is about to jump"),
# not the purpose of the action before ("turns around to walk back").
TO_COMPLEMENT = (
    *ASPECT_VERBS,
    "go",
    "goes",
    "went",
    "gone",
    "about",
    "ready",
    "able",
    "used",
    "like",
    "prepare",
    "tend",
    "plan",
    "learn",
    "how",
    "order",
    "enough",
    "wish",
    "intend",
    "ought",
    "have",
    "has",
    "had",
    "get",
    "got",
    "supposed",
    "likely",
    "unable",
    "going",
    "trying",
    "starting",
    "beginning",
    "preparing",
    "getting",
    "wanting",
    "continuing",
    "proceeding",
    "seems",
    "starts",
    "begins",
    "tries",
    "wants",
    "needs",
    "continues",
    "proceeds",
    "prepares",
    "decides",
    "manages",
    "attempts",
    "appears",
    "is",
    "are",
    "was",
    "were",
)
# "continues", "keeps going", "carries on": the action before goes on (a clause of its own).
CONTINUE = (
    r"(?:continu\w*|keeps?|keeping|kept|carr(?:y|ies|ied|ying) on|goes on|go on|going on|went on|proceeds?|"
    r"proceeding|resumes?|resuming)"
    r"(?: (?:on|going|moving|forwards?|ahead|again|straight|his|her|their|its|the|same|way|path|route|course|"
    r"movement|motion))*"
)
# "recovers", "regains balance": after a push or a stumble, the end of the reaction, not an action.
RECOVER = (
    r"(?:recover\w*|regain\w*|gains? (?:\w+ )?balance|rebalanc\w*|counterbalanc\w*|compensat\w*|"
    r"stabili[sz]\w*|balanc\w*|catch\w* (?:himself|herself|itself|themselves|(?:his |her |their |its )?"
    r"(?:steps?|balance|footing|fall)))"
)
SUBJECT_WORDS = (
    "person",
    "human",
    "man",
    "woman",
    "someone",
    "somebody",
    "subject",
    "figure",
    "individual",
    "guy",
    "girl",
    "boy",
    "child",
    "kid",
    "lady",
    "gentleman",
    "adult",
    "people",
    "actor",
    "performer",
    "character",
    "player",
    "dancer",
    "athlete",
    "peron",
    "persons",
    "humans",
    "men",
    "women",
    "he",
    "she",
    "they",
    "it",
    "somone",
)
PRONOUNS = ("he", "she", "they", "it", "him", "her", "them", "his", "its", "their", "himself", "herself", "itself")

NUMBERS = {
    "one": 1,
    "two": 2,
    "three": 3,
    "four": 4,
    "five": 5,
    "six": 6,
    "seven": 7,
    "eight": 8,
    "nine": 9,
    "ten": 10,
    "eleven": 11,
    "twelve": 12,
    "fifteen": 15,
    "twenty": 20,
    "thirty": 30,
    "forty": 40,
    "forty five": 45,
    "fortyfive": 45,
    "ninety": 90,
    "hundred": 100,
    "a hundred": 100,
    "one hundred": 100,
    "hundred and eighty": 180,
    "one hundred and eighty": 180,
    "hundred eighty": 180,
    "one hundred eighty": 180,
    "three hundred sixty": 360,
    "three hundred and sixty": 360,
}
COUNT_WORDS = {"once": 1, "twice": 2, "thrice": 3, "a couple of times": 2, "a few times": 3, "several times": 3}
# A few common misspellings of the words above (whole words only).
SPELLING = {
    "walkes": "walks",
    "wals": "walks",
    "walkign": "walking",
    "streching": "stretching",
    "streches": "stretches",
    "streched": "stretched",
    "perfoms": "performs",
    "perfom": "perform",
    "joggs": "jogs",
    "quater": "quarter",
    "rigth": "right",
    "rigt": "right",
    "foreward": "forward",
    "forwad": "forward",
    "degress": "degrees",
    "cirle": "circle",
    "cricle": "circle",
    "sqaut": "squat",
    "beeing": "being",
    "lef": "left",
    "stpes": "steps",
    "jumpes": "jumps",
    "clock wise": "clockwise",
    "turnaround": "turn around",
    "sitestep": "sidestep",
}
# Misspelt joining words (typed captions get the commonest words wrong most often). Read at the
# token level by the splitter, so a misspelt "and" or "then" still joins two clauses.
JOIN_TYPOS = {"anf": "and", "adn": "and", "amd": "and", "annd": "and", "nad": "and", "tehn": "then",
              "thne": "then", "hten": "then", "thenn": "then", "denn": "then"}  # fmt: skip
