component jogprobe "Touch-probe switch of the Measure-in-JOG HMI, fed from the scenario's scene, with an encoder-like latch";
description """
The HMI arms it before every motion with the straight path of that motion (start p0, unit
direction d) and the path length s_switch at which the true probe ball, having touched the
scene, has travelled through its pre-travel (computed in Python from the same scene truth the
simulator uses). Every servo period it projects the joint positions onto the path,
s = (pos - p0) . d. When s crosses s_switch between two samples the switching instant is
interpolated inside the period; the probe signal (probe-out, wired to motion.probe-input)
comes latency seconds later, and at that instant the position is latched, again interpolated
between the two samples that bracket it, the way a hardware encoder latch (Mesa
probe-latch) captures the counts on the input edge instead of at the next servo tick. The latch
is therefore independent of the feed and of the servo period; motion.probe-input still stops
the move 1-2 servo periods later, as on a real control.

Re-arming: the HMI writes the path pins first and changes seq last; a new seq resets the
state. An s_switch already reached when armed (a deflected probe pressing deeper) switches
at once.
""";
license "GPL";
author "Measure-in-JOG HMI";
pin in float pos_x "joint 0 position (machine X)";
pin in float pos_y "joint 1 position (machine Y)";
pin in float pos_z "joint 2 position (machine Z)";
pin in float p0_x; pin in float p0_y; pin in float p0_z;
pin in float d_x; pin in float d_y; pin in float d_z;
pin in float s_switch = 1e30 "path length to the switching point (contact + pre-travel)";
pin in float latency "signal delay switch -> latch and probe input, seconds";
pin in s32 seq "changed last by the HMI: arms the comparator for the new path";
pin out bit probe_out "the probe signal";
pin out float latch_x; pin out float latch_y; pin out float latch_z;
pin out float latch_s "path length of the latched position";
pin out float s "path length of the current position";
pin out s32 trips "count of latches since loading";
pin out s32 armed "the seq the comparator is armed for";
pin out s32 latched_seq "the seq of the newest latch";
variable int last_seq = 0;
variable int state = 3;
variable double t = 0;
variable double t_sig = 0;
variable double prev_s = 0;
variable double prev_x = 0;
variable double prev_y = 0;
variable double prev_z = 0;
function _ fp;
;;
FUNCTION(_) {
    double x = pos_x, y = pos_y, z = pos_z;
    double sn = (x - p0_x) * d_x + (y - p0_y) * d_y + (z - p0_z) * d_z;
    s = sn;
    if (seq != last_seq) {          /* armed for a new path */
        last_seq = seq;
        armed = seq;
        probe_out = 0;
        t = 0;
        state = 0;
        prev_s = sn; prev_x = x; prev_y = y; prev_z = z;
        if (sn >= s_switch) { state = 1; t_sig = latency; }
    } else {
        t += fperiod;
    }
    if (state == 0 && prev_s < s_switch && sn >= s_switch) {
        /* the switching instant, interpolated between the two samples */
        double f = (s_switch - prev_s) / (sn - prev_s);
        t_sig = t - fperiod + f * fperiod + latency;
        state = 1;
    }
    if (state == 1 && t >= t_sig) {
        /* the latch instant lies in (t - fperiod, t]: interpolate the position there */
        double f = 1.0;
        if (fperiod > 0) f = 1.0 - (t - t_sig) / fperiod;
        if (f < 0) f = 0;
        if (f > 1) f = 1;
        latch_x = prev_x + f * (x - prev_x);
        latch_y = prev_y + f * (y - prev_y);
        latch_z = prev_z + f * (z - prev_z);
        latch_s = (latch_x - p0_x) * d_x + (latch_y - p0_y) * d_y + (latch_z - p0_z) * d_z;
        probe_out = 1;
        trips++;
        latched_seq = seq;
        state = 2;
    }
    prev_s = sn; prev_x = x; prev_y = y; prev_z = z;
}
