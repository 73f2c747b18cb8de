/*
 * The joint against the simulator's physics (tools/j288-sim/servo_model.c: rotor inertia,
 * friction, the servo's own law tau = T + kp (p_des - p) + kd (w_des - w) saturated at its
 * torque), stepped in simulated time: a reply and a command every millisecond, no wall clock.
 * What is checked is the simulator's truth (its output angle), not the library's view:
 * - soft limits in every mode: speed and torque targets toward a limit stop within 0.05 rad of
 *   it (the reproduction: limits [-1.5, 1.5], pos = <current>, speed 1, kp 0, kd 1
 *   every cycle for 3 s ended at 3.68 rad), set every cycle or once through the binding; a
 *   joint beyond its range is brought back by a speed or a torque toward it;
 * - a continuous joint (a wheel) at 10 rad/s for 60 s keeps its angle exactly.
 * The float API (j288/joint.h) as Python, the runner and the bridge drive it.
 */
#include "unity.h"

#include <math.h>
#include <string.h>

#include "fake_port.h"
#include "j288/j288.h"
#include "servo_model.h"

void setUp(void) {}
void tearDown(void) {}

#define ID 1u
#define CYCLE_US 1000u
#define NEAR 0.05 /* rad: "stops within 0.05 rad of the limit" */

static j288_sim_servo_t sim;
static j288_joint_t joint;
static uint64_t now_us;
static j288_cmd_raw_t in_force; /* what the servo obeys: the last command accepted */
static unsigned refused;

static double truth(void)
{
    j288_sim_truth_t t;
    j288_sim_servo_truth(&sim, &t);
    return t.theta;
}

/* The servo at output angle theta (phase c), a joint on it with limits [lo, hi] (0, 0: none
 * but the default), known after its start. */
static void setup(double theta, double lo, double hi, bool continuous)
{
    j288_joint_config_t c;
    int i;

    memset(&c, 0, sizeof c);
    c.id = ID;
    c.pos_min = (j288_real_t)lo;
    c.pos_max = (j288_real_t)hi;
#ifndef OLD_API
    c.continuous = continuous;
#else
    (void)continuous;
#endif
    now_us = 0u;
    refused = 0u;
    j288_sim_servo_init(&sim, ID, NULL, 0.4, theta);
    (void)j288_joint_lock_command(&joint, &in_force);
    in_force.id = ID;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    for (i = 0; i < 20 && !j288_joint_state(&joint)->known; i++) {
        j288_reply_raw_t r;
        now_us += CYCLE_US;
        j288_sim_servo_advance(&sim, now_us);
        j288_sim_servo_reply(&sim, &r);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    }
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
}

/* One cycle: the servo's reply to the joint, then the joint's command for t, made now as a
 * control loop does every cycle; a refused target leaves the last command in force (as a
 * scheduler's slot does), and is counted. */
static void cycle(const j288_joint_target_t *t)
{
    j288_reply_raw_t r;
    j288_cmd_raw_t made;
    now_us += CYCLE_US;
    j288_sim_servo_advance(&sim, now_us);
    j288_sim_servo_reply(&sim, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    if (j288_joint_command(&joint, t, &made, NULL) == J288_OK) {
        in_force = made;
    } else {
        refused++;
    }
    TEST_ASSERT_TRUE(j288_sim_servo_command(&sim, &in_force, now_us));
}

/* A speed or torque target, remade every cycle for `seconds`, pos = the joint's angle (what
 * the script sent); the largest angle reached, as the truth says. */
static double run_every_cycle(double speed, double torque, double kd, double seconds,
                              double *extreme)
{
    unsigned n;
    *extreme = truth();
    for (n = 0; n < (unsigned)(seconds * 1e6 / CYCLE_US); n++) {
        j288_joint_target_t t;
        j288_joint_target_init(&joint, &t);
        t.pos = j288_joint_state(&joint)->pos;
        t.speed = (j288_real_t)speed;
        t.torque = (j288_real_t)torque;
        t.kp = 0;
        t.kd = (j288_real_t)kd;
        cycle(&t);
        *extreme = ((speed + torque > 0.0) == (truth() > *extreme)) ? truth() : *extreme;
    }
    return truth();
}

static void print_rad(const char *what, double x)
{
    long long n = llround(fabs(x) * 1e4);
    UnityPrint("  ");
    UnityPrint(what);
    UnityPrint(x < 0.0 ? ": -" : ": ");
    UnityPrintNumber((UNITY_INT)(n / 10000));
    UnityPrint(".");
    UnityPrintNumber((UNITY_INT)(n % 10000 / 1000));
    UnityPrintNumber((UNITY_INT)(n % 1000 / 100));
    UnityPrintNumber((UNITY_INT)(n % 100 / 10));
    UnityPrintNumber((UNITY_INT)(n % 10));
    UnityPrint(" rad");
    UNITY_PRINT_EOL();
}

/* The reproduction: 1 rad/s, kd 1, every cycle for 3 s toward 1.5. */
static void test_speed_toward_a_limit_stops_there(void)
{
    double end, most;
    setup(0.0, -1.5, 1.5, false);
    end = run_every_cycle(1.0, 0.0, 1.0, 3.0, &most);
    print_rad("speed 1 rad/s for 3 s, limit 1.5: end", end);
    print_rad("  furthest", most);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, 1.5, end);
    TEST_ASSERT_TRUE(most <= 1.5 + NEAR);
    TEST_ASSERT_EQUAL_UINT(0u, refused);
    /* A faster one, down: 5 rad/s with kd 2. */
    setup(0.0, -1.5, 1.5, false);
    end = run_every_cycle(-5.0, 0.0, 2.0, 3.0, &most);
    print_rad("speed -5 rad/s for 3 s, limit -1.5: end", end);
    print_rad("  furthest", most);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, -1.5, end);
    TEST_ASSERT_TRUE(most >= -1.5 - NEAR);
}

static void test_torque_toward_a_limit_stops_there(void)
{
    double end, most;
    setup(0.0, -1.5, 1.5, false);
    end = run_every_cycle(0.0, -2.0, 0.0, 3.0, &most); /* 2 N*m, no damping of its own */
    print_rad("torque -2 N*m for 3 s, limit -1.5: end", end);
    print_rad("  furthest", most);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, -1.5, end);
    TEST_ASSERT_TRUE(most >= -1.5 - NEAR);
    setup(-1.0, -1.5, 1.5, false);
    end = run_every_cycle(0.0, 5.0, 0.0, 3.0, &most);
    print_rad("torque 5 N*m for 3 s, limit 1.5: end", end);
    print_rad("  furthest", most);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, 1.5, end);
    TEST_ASSERT_TRUE(most <= 1.5 + NEAR);
}

/* Beyond the limit (a load pushed it there, the servo off): a speed or a torque back toward
 * the range is taken and brings it back; one further out gets the limit law, which pulls it
 * back to the limit. */
static void test_beyond_the_limit_speed_or_torque_brings_it_back(void)
{
    double end, most;
    setup(1.8, -1.5, 1.5, false);
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->beyond_limit);
    end = run_every_cycle(-0.5, 0.0, 1.0, 2.0, &most);
    print_rad("from 1.8, speed -0.5 rad/s for 2 s: end", end);
    TEST_ASSERT_TRUE(end < 1.5 - 0.3);
    TEST_ASSERT_EQUAL_UINT(0u, refused); /* back toward the range: taken from the start */
    setup(1.8, -1.5, 1.5, false);
    end = run_every_cycle(0.0, -1.0, 0.0, 2.0, &most);
    print_rad("from 1.8, torque -1 N*m for 2 s: end", end);
    TEST_ASSERT_TRUE(end < 1.5 + NEAR);
    setup(1.8, -1.5, 1.5, false);
    end = run_every_cycle(0.5, 0.0, 1.0, 3.0, &most);
    print_rad("from 1.8, speed +0.5 rad/s (outward) for 3 s: end", end);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, 1.5, end);
}

#ifndef OLD_API
/* The same speed target set once through the binding, as the runner and the bridge do: the
 * binding remakes its command from every reply. */
static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;
static j288_joint_bus_t jb;

static void test_speed_set_once_through_the_binding(void)
{
    j288_sched_config_t sc;
    j288_joint_target_t t;
    j288_reply_raw_t r;
    unsigned n;
    double most;

    setup(0.0, -1.5, 1.5, false);
    memset(&sc, 0, sizeof sc);
    sc.on_reply = j288_joint_bus_on_reply;
    sc.user = &jb;
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    j288_sim_servo_reply(&sim, &r);
    fake_port_add_servo(&fp, ID, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_init(&jb, &sch, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_add(&jb, &joint));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, ID, true));
    j288_joint_target_init(&joint, &t);
    t.kp = 0;
    t.kd = 1;
    t.speed = 1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_set_target(&jb, &joint, &t, NULL));
    most = truth();
    for (n = 0; n < 3000u; n++) {
        now_us += CYCLE_US;
        j288_sim_servo_advance(&sim, now_us);
        j288_sim_servo_reply(&sim, &fp.servo[ID].reply);
        /* the slot's command goes out, the servo's reply comes back into the binding */
        TEST_ASSERT_TRUE(j288_sim_servo_command(&sim, &j288_sched_slot(&sch, ID)->cmd, now_us));
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
        TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 20000000u));
        most = (truth() > most) ? truth() : most;
    }
    print_rad("speed 1 rad/s set once through the binding, 3 s: end", truth());
    print_rad("  furthest", most);
    TEST_ASSERT_DOUBLE_WITHIN(NEAR, 1.5, truth());
    TEST_ASSERT_TRUE(most <= 1.5 + NEAR);
}

#endif

/* The joint's angle, exactly: the core's (Q24, int64). The facade's j288_real_t holds it only
 * to its own precision (a float's step at 600 rad is 61 urad). */
static double exact_angle(void)
{
#ifndef OLD_API
    return (double)j288_jointq_state(j288_joint_core(&joint))->pos / 16777216.0;
#else
    return (double)j288_joint_state(&joint)->pos;
#endif
}

/* A wheel: 10 rad/s for 60 s (600 rad), the angle the joint reports against the truth at
 * every reply: within the start's error and the rotor's resolution, never lost. (Before
 * continuous joints, -DOLD_API: the widest range the float layer took, +-64 rad.) */
static void test_wheel_for_a_minute(void)
{
    double start_err = 0.0, worst = 0.0;
    unsigned n;

#ifndef OLD_API
    setup(0.3, 0.0, 0.0, true);
#else
    setup(0.3, -64.0, 64.0, false);
#endif
    for (n = 0; n < 60000u; n++) {
        j288_joint_target_t t;
        double e;
        j288_joint_target_init(&joint, &t);
        t.kp = 0;
        t.kd = 20;
        t.speed = 10;
        cycle(&t);
        e = exact_angle() - truth();
        if (n == 0u) {
            start_err = e;
            TEST_ASSERT_TRUE(fabs(e) < 0.4e-3); /* the start: half an OutPos count */
        }
        worst = (fabs(e - start_err) > worst) ? fabs(e - start_err) : worst;
    }
    print_rad("a wheel at 10 rad/s for 60 s: angle", truth());
    UnityPrint("  its error beyond the start's, worst (nrad): ");
    UnityPrintNumber((UNITY_INT)llround(worst * 1e9));
    UNITY_PRINT_EOL();
    TEST_ASSERT_TRUE(truth() > 560.0);
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    TEST_ASSERT_TRUE(worst < 1e-6); /* the rotor's 0.66 urad LSB */
    TEST_ASSERT_EQUAL_UINT(0u, refused);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_speed_toward_a_limit_stops_there);
    RUN_TEST(test_torque_toward_a_limit_stops_there);
    RUN_TEST(test_beyond_the_limit_speed_or_torque_brings_it_back);
#ifndef OLD_API
    RUN_TEST(test_speed_set_once_through_the_binding);
#endif
    RUN_TEST(test_wheel_for_a_minute);
    return UNITY_END();
}
