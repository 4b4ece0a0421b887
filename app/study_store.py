"""Storage of a user study: participants, trials and votes, through SQLAlchemy.

SQLite by default (``$MMS_STUDY_DB``, a file path; default ``study.sqlite`` in the working
directory); ``$MMS_STUDY_DB_URL`` takes any SQLAlchemy URL instead, e.g. a PostgreSQL one for
a hosted space with several replicas.

Durability: every write is one short transaction, committed before the API answers. SQLite
runs in WAL mode with ``synchronous=FULL``, so a committed vote survives a kill -9 or a power
cut; a crash between trials loses at most the trial in flight (tested by killing the server
during a simulated study). One vote per trial is a UNIQUE constraint, so a replayed vote fails
in the database even when two requests race. Participants and trials are addressed by random
128-bit tokens, never by their row ids, so trial ids cannot be guessed or forged.
"""

from __future__ import annotations

import json
import os
import secrets
import sqlite3
import time
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from sqlalchemy import (
    Boolean,
    DateTime,
    Float,
    ForeignKey,
    Integer,
    String,
    Text,
    UniqueConstraint,
    create_engine,
    event,
    func,
    inspect,
    select,
    update,
)
from sqlalchemy.engine import Connection, Engine
from sqlalchemy.exc import IntegrityError, OperationalError
from sqlalchemy.orm import DeclarativeBase, Mapped, Session, mapped_column, relationship, sessionmaker


def _now() -> datetime:
    return datetime.now(UTC).replace(tzinfo=None)  # stored as naive UTC (SQLite has no zones)


def new_token() -> str:
    return secrets.token_hex(16)


class Base(DeclarativeBase):
    pass


class Participant(Base):
    __tablename__ = "participants"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    token: Mapped[str] = mapped_column(String(32), unique=True, index=True)  # the anonymous id
    study: Mapped[str] = mapped_column(String(64), index=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=_now)
    trials: Mapped[list[Trial]] = relationship(back_populates="participant", order_by="Trial.position")


class Trial(Base):
    """One comparison shown to one participant: A is shown on the left, B on the right."""

    __tablename__ = "trials"
    __table_args__ = (UniqueConstraint("participant_id", "position"),)
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    token: Mapped[str] = mapped_column(String(32), unique=True, index=True)
    participant_id: Mapped[int] = mapped_column(ForeignKey("participants.id"), index=True)
    position: Mapped[int] = mapped_column(Integer)  # 0-based trial number of this participant
    prompt: Mapped[str] = mapped_column(Text)
    custom_prompt: Mapped[bool] = mapped_column(Boolean, default=False)
    seconds: Mapped[float] = mapped_column(Float)
    seed: Mapped[int] = mapped_column(Integer)
    pair: Mapped[str] = mapped_column(String(128), index=True)  # "m1|m2", sorted
    method_a: Mapped[str] = mapped_column(String(64))
    method_b: Mapped[str] = mapped_column(String(64))
    swapped: Mapped[bool] = mapped_column(Boolean)  # A is the pair's second method
    gen_seconds_a: Mapped[float] = mapped_column(Float)
    gen_seconds_b: Mapped[float] = mapped_column(Float)
    # the sampler that made each motion ("quality" or "fast"): a method's default can change
    # between server versions mid-study. NULL in trials stored before it was recorded
    sampler_a: Mapped[str | None] = mapped_column(String(16), nullable=True)
    sampler_b: Mapped[str | None] = mapped_column(String(16), nullable=True)
    cached_a: Mapped[bool] = mapped_column(Boolean, default=False)
    cached_b: Mapped[bool] = mapped_column(Boolean, default=False)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=_now)
    participant: Mapped[Participant] = relationship(back_populates="trials")
    vote: Mapped[Vote | None] = relationship(back_populates="trial", uselist=False)


class Vote(Base):
    __tablename__ = "votes"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    trial_id: Mapped[int] = mapped_column(ForeignKey("trials.id"), unique=True)  # one vote per trial
    answer: Mapped[str] = mapped_column(String(16))  # A, B, tie, both_bad
    criteria: Mapped[str] = mapped_column(Text, default="{}")  # JSON {criterion: A|B|tie}
    decision_seconds: Mapped[float] = mapped_column(Float)  # trial shown -> vote stored
    watched_a: Mapped[bool | None] = mapped_column(Boolean, nullable=True)  # as the page reports
    watched_b: Mapped[bool | None] = mapped_column(Boolean, nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=_now)
    trial: Mapped[Trial] = relationship(back_populates="vote")


class VoteRejected(ValueError):
    """A vote that cannot be stored: unknown or foreign trial, replay, bad answer."""


@dataclass(frozen=True)
class NewTrial:
    prompt: str
    seconds: float
    seed: int
    method_a: str
    method_b: str
    swapped: bool
    gen_seconds_a: float
    gen_seconds_b: float
    cached_a: bool = False
    cached_b: bool = False
    custom_prompt: bool = False
    sampler_a: str | None = None
    sampler_b: str | None = None


def database_url() -> str:
    url = os.environ.get("MMS_STUDY_DB_URL")
    if url:
        return url
    return "sqlite:///" + os.path.abspath(os.environ.get("MMS_STUDY_DB", "study.sqlite"))


def make_engine(url: str) -> Engine:
    if url.startswith("sqlite"):
        engine = create_engine(url, connect_args={"timeout": 30, "check_same_thread": False})

        @event.listens_for(engine, "connect")
        def _pragmas(conn, _record) -> None:  # every new SQLite connection
            cur = conn.cursor()
            _wal(cur)
            cur.execute("PRAGMA synchronous=FULL")  # a commit is on disk before we answer
            cur.execute("PRAGMA foreign_keys=ON")
            cur.close()

        return engine
    return create_engine(url, pool_pre_ping=True)


def _wal(cur: sqlite3.Cursor, timeout: float = 30.0) -> None:
    """Put the database in WAL mode (it stays so, in the file). Switching needs the file to
    itself, and SQLite answers a switch that meets another connection with "database is
    locked" at once, without its busy timeout: replicas opening a new database together hit
    that (1 in 20 starts of six). So a busy switch is retried until another has made it."""
    deadline = time.monotonic() + timeout
    delay = 0.005
    while True:
        try:
            if cur.execute("PRAGMA journal_mode").fetchone()[0] == "wal":
                return
            cur.execute("PRAGMA journal_mode=WAL")
            return
        except sqlite3.OperationalError as e:
            if "locked" not in str(e) or time.monotonic() > deadline:
                raise
            time.sleep(delay)
            delay = min(delay * 2, 0.2)


# any fixed 64-bit key: the advisory lock that serialises table creation across replicas
_CREATE_LOCK = 0x4D4D535354554459  # "MMSSTUDY"


#: how long a schema change waits for a table's lock on PostgreSQL before the start-up gives up
ALTER_LOCK_TIMEOUT_S = 10.0
_LOCK_NOT_AVAILABLE = "55P03"  # PostgreSQL's SQLSTATE for a lock_timeout


def create_tables(engine: Engine) -> None:
    """Create the tables that are missing and add the columns missing from older ones, also
    when several processes (replicas of a space) start together on an empty database.
    PostgreSQL: two concurrent CREATE TABLEs of the same name fail with a duplicate
    ``pg_type`` row, so there the check-and-create runs under a transaction-scoped advisory
    lock. SQLite has no such lock: a creator that finds the table made meanwhile ("already
    exists") checks again, at most once per table.

    On PostgreSQL a schema change (an ALTER TABLE, a foreign key to an existing table) queues
    for a lock on the table, and every query on it queues behind: a replica of an older
    version holding a transaction open would stall the whole study while this one waited.
    Past ``ALTER_LOCK_TIMEOUT_S`` the start-up stops with a message instead, and the running
    replicas go on."""
    attempts = len(Base.metadata.tables) + 1
    for attempt in range(attempts):
        try:
            with engine.begin() as conn:
                if engine.dialect.name == "postgresql":
                    conn.execute(select(func.pg_advisory_xact_lock(_CREATE_LOCK)))
                    # after the advisory lock: replicas starting together wait on it in turn
                    conn.exec_driver_sql(f"SET LOCAL lock_timeout = '{int(ALTER_LOCK_TIMEOUT_S * 1000)}ms'")
                Base.metadata.create_all(conn)
                _add_missing_columns(conn)
            return
        except OperationalError as e:
            # psycopg 3 names the SQLSTATE sqlstate, psycopg2 pgcode
            if _LOCK_NOT_AVAILABLE in (getattr(e.orig, "sqlstate", None), getattr(e.orig, "pgcode", None)):
                raise RuntimeError(
                    f"could not change the study's tables within {ALTER_LOCK_TIMEOUT_S:g} s: another "
                    f"connection holds them (a replica of an older version still running?). Stop it, or "
                    f"start this one again when it is idle. (It waited on: {e.statement})"
                ) from None
            if not any(m in str(e) for m in ("already exists", "duplicate column")) or attempt == attempts - 1:
                raise


def _add_missing_columns(conn: Connection) -> None:
    """A database made by an older version keeps its tables and rows; the nullable columns
    added since (``Trial.sampler_a`` / ``sampler_b``) are added to it, NULL in old rows.
    Only nullable columns are added this way: a required one would need a value for them."""
    have = inspect(conn)
    for table in Base.metadata.sorted_tables:
        present = {c["name"] for c in have.get_columns(table.name)}
        for col in table.columns:
            if col.name in present:
                continue
            if not col.nullable:
                raise RuntimeError(f"the database's {table.name} table lacks the required column {col.name}")
            kind = col.type.compile(dialect=conn.dialect)
            quote = conn.dialect.identifier_preparer.quote
            conn.exec_driver_sql(f"ALTER TABLE {quote(table.name)} ADD COLUMN {quote(col.name)} {kind}")


class StudyStore:
    """Participants, trials and votes of one or more studies in one database."""

    def __init__(self, url: str | None = None) -> None:
        self.url = url or database_url()
        self.engine = make_engine(self.url)
        create_tables(self.engine)
        self._session = sessionmaker(self.engine, expire_on_commit=False)

    def close(self) -> None:
        self.engine.dispose()

    # ---------------------------------------------------------------- writes
    def new_participant(self, study: str) -> str:
        token = new_token()
        with self._session.begin() as s:
            s.add(Participant(token=token, study=study))
        return token

    def add_trial(self, participant: str, trial: NewTrial) -> tuple[str, int]:
        """Store the participant's next trial; returns (trial token, position)."""
        with self._session.begin() as s:
            p = self._participant(s, participant)
            position = s.scalar(select(func.count(Trial.id)).where(Trial.participant_id == p.id)) or 0
            pair = "|".join(sorted((trial.method_a, trial.method_b)))
            token = new_token()
            s.add(
                Trial(
                    token=token,
                    participant_id=p.id,
                    position=position,
                    pair=pair,
                    **trial.__dict__,
                )
            )
        return token, position

    def record_vote(
        self,
        participant: str,
        trial: str,
        answer: str,
        criteria: dict[str, str] | None = None,
        watched: tuple[bool | None, bool | None] = (None, None),
        allowed_answers: tuple[str, ...] = ("A", "B", "tie", "both_bad"),
        allowed_criteria: dict[str, tuple[str, ...]] | None = None,
    ) -> int:
        """Store one vote in its own transaction; returns the number of votes of this participant.

        Raises VoteRejected for an unknown trial, a trial of another participant, a second
        vote on a trial, or an answer / criterion not offered.
        """
        if answer not in allowed_answers:
            raise VoteRejected(f"answer must be one of {', '.join(allowed_answers)}")
        criteria = dict(criteria or {})
        if allowed_criteria is not None:
            for k, v in criteria.items():
                if k not in allowed_criteria or v not in allowed_criteria[k]:
                    raise VoteRejected(f"unknown criterion or answer: {k!r}={v!r}")
        try:
            with self._session.begin() as s:
                t = s.scalar(select(Trial).where(Trial.token == str(trial)))
                if t is None or t.participant.token != str(participant):
                    raise VoteRejected("unknown trial for this participant")
                if t.vote is not None:
                    raise VoteRejected("this trial already has a vote")
                decision = (_now() - t.created_at).total_seconds()
                s.add(
                    Vote(
                        trial_id=t.id,
                        answer=answer,
                        criteria=json.dumps(criteria, sort_keys=True),
                        decision_seconds=decision,
                        watched_a=watched[0],
                        watched_b=watched[1],
                    )
                )
                s.flush()
                return self._vote_count(s, t.participant_id)
        except IntegrityError:  # a concurrent replay of the same vote lost the race
            raise VoteRejected("this trial already has a vote") from None

    # ---------------------------------------------------------------- reads
    @staticmethod
    def _participant(s: Session, token: str) -> Participant:
        p = s.scalar(select(Participant).where(Participant.token == str(token)))
        if p is None:
            raise VoteRejected("unknown participant")
        return p

    @staticmethod
    def _vote_count(s: Session, participant_id: int) -> int:
        return s.scalar(select(func.count(Vote.id)).join(Trial).where(Trial.participant_id == participant_id)) or 0

    def progress(self, participant: str) -> dict[str, Any]:
        """Trials shown, votes given, the seen (pair, prompt) combinations, the pairs shown in
        trial order, and the open trial."""
        with self._session() as s:
            p = self._participant(s, participant)
            trials = list(p.trials)
            open_trial = next((t for t in trials if t.vote is None), None)
            return {
                "study": p.study,
                "trials": len(trials),
                "votes": sum(t.vote is not None for t in trials),
                "seen": {(t.pair, t.prompt) for t in trials},
                "pairs": [t.pair for t in trials],  # in trial order
                "open": None if open_trial is None else open_trial.token,
            }

    def open_trial(self, participant: str) -> Trial | None:
        """The participant's latest trial if it has no vote yet."""
        with self._session() as s:
            p = self._participant(s, participant)
            t = s.scalar(select(Trial).where(Trial.participant_id == p.id).order_by(Trial.position.desc()).limit(1))
            if t is None or t.vote is not None:
                return None
            return t

    def combo_counts(self, study: str) -> dict[tuple[str, str, int], int]:
        """How many trials each (pair, prompt, seed) has had in this study (for balancing)."""
        with self._session() as s:
            rows = s.execute(
                select(Trial.pair, Trial.prompt, Trial.seed, func.count(Trial.id))
                .join(Participant)
                .where(Participant.study == study, Trial.custom_prompt.is_(False))
                .group_by(Trial.pair, Trial.prompt, Trial.seed)
            ).all()
        return {(pair, prompt, seed): n for pair, prompt, seed, n in rows}

    def pair_counts(self, study: str) -> dict[str, int]:
        with self._session() as s:
            rows = s.execute(
                select(Trial.pair, func.count(Trial.id))
                .join(Participant)
                .where(Participant.study == study)
                .group_by(Trial.pair)
            ).all()
        return dict(rows)

    def set_samplers(
        self,
        token: str,
        recorded: tuple[str | None, str | None],
        sampler_a: str | None,
        sampler_b: str | None,
        made_a: tuple[float, bool] | None = None,
        made_b: tuple[float, bool] | None = None,
    ) -> bool:
        """Record the samplers that now make an open trial's motions (``StudyService.resume``
        when a recorded one is no longer offered), and for a side whose motion was made
        anew, ``made_a`` / ``made_b`` = (seconds it took, whether it came from the cache):
        the record then describes the motion shown, not the first one. One conditional
        UPDATE, taken only while the trial is unvoted and still records ``recorded`` (the
        samplers its caller read): a vote stored meanwhile keeps the trial as it was cast,
        and of two resumes falling back at once only the first writes (the second found
        the first's motion in the cache). True where it wrote."""
        values: dict[str, Any] = {"sampler_a": sampler_a, "sampler_b": sampler_b}
        for side, made in (("a", made_a), ("b", made_b)):
            if made is not None:
                values[f"gen_seconds_{side}"], values[f"cached_{side}"] = float(made[0]), bool(made[1])
        with self._session.begin() as s:
            done = s.execute(
                update(Trial)
                .where(
                    Trial.token == str(token),
                    ~Trial.vote.has(),
                    Trial.sampler_a.is_not_distinct_from(recorded[0]),
                    Trial.sampler_b.is_not_distinct_from(recorded[1]),
                )
                .values(**values)
                .execution_options(synchronize_session=False)
            )
            return bool(done.rowcount)

    def trial(self, token: str) -> Trial | None:
        with self._session() as s:
            return s.scalar(select(Trial).where(Trial.token == str(token)))

    def votes(self, study: str | None = None) -> list[dict[str, Any]]:
        """Every stored vote with its trial (method identities included: admin use only)."""
        q = select(Vote, Trial, Participant).join(Trial, Vote.trial_id == Trial.id).join(Participant)
        if study is not None:
            q = q.where(Participant.study == study)
        with self._session() as s:
            rows = s.execute(q.order_by(Vote.id)).all()
        out = []
        for v, t, p in rows:
            winner = {"A": t.method_a, "B": t.method_b}.get(v.answer, "")
            out.append(
                {
                    "vote_id": v.id,
                    "participant": p.token,
                    "study": p.study,
                    "trial": t.token,
                    "position": t.position,
                    "prompt": t.prompt,
                    "custom_prompt": t.custom_prompt,
                    "seconds": t.seconds,
                    "seed": t.seed,
                    "method_a": t.method_a,
                    "method_b": t.method_b,
                    "swapped": t.swapped,
                    "answer": v.answer,
                    "winner": winner,
                    "criteria": json.loads(v.criteria or "{}"),
                    "decision_seconds": v.decision_seconds,
                    "watched_a": v.watched_a,
                    "watched_b": v.watched_b,
                    "gen_seconds_a": t.gen_seconds_a,
                    "gen_seconds_b": t.gen_seconds_b,
                    "sampler_a": t.sampler_a,
                    "sampler_b": t.sampler_b,
                    "trial_created_at": t.created_at.isoformat(),
                    "voted_at": v.created_at.isoformat(),
                }
            )
        return out

    def counts(self) -> dict[str, int]:
        with self._session() as s:
            return {
                "participants": s.scalar(select(func.count(Participant.id))) or 0,
                "trials": s.scalar(select(func.count(Trial.id))) or 0,
                "votes": s.scalar(select(func.count(Vote.id))) or 0,
            }
