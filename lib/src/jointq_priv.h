/* The joint core's functions for the float facade (joint.c) and the calibration fit
 * (joint_cal.c): not part of the public API. */
#ifndef J288_JOINTQ_PRIV_H
#define J288_JOINTQ_PRIV_H

#include "j288/jointq.h"
#include "j288/units.h"

/* cfg with its defaults filled in, checked, into *out (and the middle of its range, the
 * turn labelling's centre, into *centre): J288_OK, J288_ERR_BAD_ID, J288_ERR_BAD_CONFIG. */
int j288_jointq_check_config(const j288_jointq_config_t *cfg, j288_jointq_config_t *out,
                             j288_q24_t *centre);

/* The turn choice of a configuration (filled in): the output angle (any turn, within a few
 * of 0) labelled within pi of centre, as the output-encoder frame's angle zero + direction q. */
j288_q24_t j288_jointq_label_theta(const j288_jointq_config_t *c, j288_q24_t centre,
                                   j288_q24_t theta);

/* j288_jointq_state() and j288_jointq_config() inline, for the facade's path from each reply
 * (no call there), and the middle of the joint's range (the turn labelling's centre) for the
 * calibration fit. j not NULL. */
static inline const j288_jointq_state_t *j288_jointq_state_of(const j288_jointq_t *j)
{
    return &j->st;
}

static inline const j288_jointq_config_t *j288_jointq_config_of(const j288_jointq_t *j)
{
    return &j->cfg;
}

static inline j288_q24_t j288_jointq_centre(const j288_jointq_t *j)
{
    return j->centre;
}

/* a - b in rotor LSB, modulo 2^32 (the wire's int32 may wrap), as an int32. */
int32_t j288_jointq_lsb_diff(int32_t a, int32_t b);

/* The binding's work after joint j (bound in jb) took the reply of slot with these events:
 * the lock while unknown, the kept target's command, the events to on_event. */
void j288_jointq_after_reply(j288_jointq_bus_t *jb, j288_jointq_t *j, const j288_slot_t *slot,
                             unsigned events);

#if J288_CONFIG_SI
/* A Q24 angle as a real (joint.c's conversion at the facade's edge). */
j288_real_t j288_joint_real_of_q24(j288_q24_t q);
#endif

#endif /* J288_JOINTQ_PRIV_H */
