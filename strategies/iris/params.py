"""`IrisParams`: every number of the four IRIS strategies, with its unit and reason; the command names they act on."""

from __future__ import annotations

from dataclasses import dataclass

from arena.navigation import PARAMS
from arena.navigation.fsfm import FSFMParams
from arena.navigation.pid import PIDParams
from arena.navigation.sfm import SFMParams
from arena.strategies import skills as S
from arena.strategies.world import FusionParams

Vec = tuple[float, float]

PLAY = "START"
WALL_PIECES = frozenset({"KICKOFF", "FREEKICK", "THROWIN", "CORNER"})  # advance defense: wall and mark at these


# slots: the robots read these fields many times a tick, and a slot is read faster than a
# key of an instance dict this large (some 60 fields)
@dataclass(frozen=True, slots=True)
class IrisParams:
    advance: bool = False  # advance attack and defense (Fig. 7) instead of the basic play
    dynamic: bool = False  # dynamic roles (Fig. 6 inputs a and d) instead of static ones
    navigator: str = "f-sfm"  # arena.navigation name
    cruise: float = 2.5  # [m/s] travel speed, same for all four strategies
    dribble_speed: float = 1.5  # [m/s] while holding the ball
    approach_speed: float = 1.8  # [m/s] final approach onto the ball
    kick_speed: float = 8.0  # [m/s] shot speed (the kicker's full power), same for all four strategies
    basic_shoot_distance: float = 5.0  # [m] basic: kick from this distance to the goal centre
    advance_shoot_distance: float = 4.5  # [m] advance: shoot within this distance if the line is clear
    close_shot: float = 1.8  # [m] advance: shoot anyway this close
    pass_arrive: float = 1.5  # [m/s] ball speed at the receiver
    dribble_omega: float = 2.4  # [rad/s] turn-rate cap with the ball (the dribbler loses it at 3)
    max_omega: float = 5.0  # [rad/s] turn-rate cap without the ball
    aim_tolerance: float = 0.08  # [rad] largest heading error at which a shot or pass is taken
    shot_spread: float = 0.15  # [m] ... and at most this much off the aim point where the ball gets there
    min_aim_tolerance: float = 0.025  # [rad] (noise floor: the heading is sensed with 0.01 rad sigma)
    pass_lead: float = 0.8  # [m] a pass goes this far ahead of the receiver, towards the goal
    pass_rest: float = 1.0  # [s] after a pass the passer leaves the ball to the receiver this long
    k_pos: float = 2.5  # [1/s] arrival slow-down: speed <= k_pos * distance
    direct_range: float = 0.7  # [m] closer than this to a target the robot drives straight at it
    # [m] robots farther than this are no obstacle: beyond 1.5 m the F-SFM social force
    # (paper 1 eq. 6, sigma 0.3 m, r_ij 0.5 m) is below 2 % of the goal force at cruise speed
    obstacle_range: float = 1.5
    setpiece_distance: float = 2.0  # [m] opponents keep this far from a set-piece spot
    setpiece_behind: float = 0.5  # [m] the taker stands this far behind the ball
    chase_hysteresis: float = 0.4  # [m] the current chaser counts this much nearer
    possession_radius: float = 0.4  # [m] an opponent this close to the ball has it
    max_hold: float = 2.5  # [s] advance: act (shoot, pass or push ahead) after holding the ball this long
    carry_limit: float = 2.0  # [m] release the ball before this straight-line carry (MSL dribble limit 3 m)
    nudge_speed: float = 1.6  # [m/s] kick the ball ahead to restart a carry at the limit
    regroup: float = 0.6  # [s] after losing the ball to a tackle, step back this long ...
    regroup_clear: float = 0.6  # [m] ... first backing straight off the ball to this far (centre to ball centre)
    regroup_distance: float = 0.9  # [m] ... to this far from the ball (basic: aside, advance: goal-side)
    cover_depth: float = -2.5  # [m] along the attack direction: the defender's place while the team attacks
    mark_zone: float = 6.5  # [m] advance defense: an opponent this close to our goal (about our half) is marked
    block_zone: float = (
        6.5  # [m] advance defense: a carrier this close to our goal is blocked, not left to the attacker
    )
    # [1/s] advance defense: the blocker drives straight onto the kick line at this speed per metre off it
    # (the plain 1 m/s per metre lets a carrier turning or circling at 1.5 m/s open a post); higher gains
    # rush the carrier into pushing fouls and long shots
    block_gain: float = 3.0
    drop_back: float = 4.5  # [m] advance defense: with the ball this close to our goal the attacker marks too
    take_angle: float = 0.5  # [rad] advance defense: the blocker takes the ball only this close to the kick line
    behind_penalty: float = (
        1.5  # [m] advance defense: extra way to the kick line for a robot not goal-side of the carrier
    )
    wall_margin: float = 0.2  # [m] advance defense: the set-piece wall stands this far beyond the 2 m the rules ask
    wall_exit_turn: float = 1.0  # [rad] ... a robot inside the 2 m circle leaves it at most this far off straight away
    pressure_range: float = 1.2  # [m] advance attack: a blocker this close leaves no room to go round it
    keeper_zone: float = 1.2  # [m] advance attack: an opponent this close to the goal centre is the keeper, no blocker
    shot_commit: float = 0.6  # [s] advance attack: once a clear shot is seen, turn and take it within this time
    stall_hold: float = 4.0  # [s] a holder still holding after this long plays the ball on (`unstall`)
    unstall_speed: float = 3.0  # [m/s]
    push_guard: float = 0.5  # [m/s] closing speed at contact with an opponent (pushing fouls above 1.5 for both)
    brake: float = 1.2  # [m/s^2] deceleration the push guard counts on (the drive gives 2)
    push_guard_range: float = 2.5  # [m] opponents closer than this (centre to centre) get the cap
    ball_contact_range: float = 0.4  # [m] held ball's centre to an opponent's centre: touching or nearly
    separate_speed: float = 0.5  # [m/s] a robot turning with the ball edges away from an opponent in contact
    contact_range: float = (
        0.65  # [m] centre to centre: the footprints (0.45 m squares) may touch (corner to corner 0.64)
    )
    contact_push: float = 0.0  # [m/s] closing speed cap towards an opponent in contact
    heading_pid: PIDParams = PIDParams(k_p=6.0, k_i=0.0, k_d=2.0)  # paper 1 eq. 16 gains for 50 Hz
    skills: S.SkillParams = S.SkillParams()
    fusion: FusionParams = FusionParams()
    overlap: float = 1.0  # [m] defender/attacker areas overlap (paper 2)
    # [1/s] the goalkeeper drives straight to its stand point at min(cruise, keeper_gain * distance);
    # 0: at 1 m/s per metre to go (`drive` without a gain)
    keeper_gain: float = 0.0

    def nav_params(self):
        if self.navigator == "f-sfm":
            return FSFMParams(sfm=SFMParams(max_speed=self.cruise, robot_radius=0.5, sigma=0.3))
        defaults = PARAMS[self.navigator]()
        return type(defaults)(
            **{**{f: getattr(defaults, f) for f in defaults.__dataclass_fields__}, "max_speed": self.cruise}
        )
