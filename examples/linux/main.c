/*
 * The smallest Linux program on j288: open a serial device, bind a bus to it, ask one servo
 * for its state and print it. Usage: linux-status DEVICE ID
 * Without hardware: build/bin/j288-sim --ids 1 --link /tmp/bus &  build/bin/linux-status /tmp/bus 1
 */
#include <stdio.h>
#include <stdlib.h>

#include "j288/j288.h"
#include "j288_serial.h"

int main(int argc, char **argv)
{
    static j288_serial_t port; /* caller-allocated: the library allocates nothing */
    static j288_bus_t bus;
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = {0};
    j288_txn_t txn;
    j288_reply_si_t si;
    char *end = NULL;
    long id = argc == 3 ? strtol(argv[2], &end, 10) : -1;
    int rc;

    if (end == NULL || *end != '\0' || id < 0 || id > (long)J288_MAX_ID) {
        fprintf(stderr, "usage: linux-status DEVICE ID(0-14)\n");
        return 2;
    }
    if (j288_serial_open(&port, argv[1], 0, NULL) != J288_OK) {
        fprintf(stderr, "linux-status: %s\n", j288_serial_error(&port));
        return 1;
    }
    j288_serial_bus_config(&port, &cfg); /* the opened baud, a reply margin for USB adapters */
    cfg.margin_us = 250000u;            /* a status read, not a control loop: be patient */
    cfg.retries = 2u;
    j288_serial_bus_init(&port, &bus, &cfg);

    /* The protocol has no read-only query: a lock command (no torque) asks for the reply. */
    cmd.id = (uint8_t)id;
    cmd.status = J288_MODE_LOCK;
    rc = j288_bus_transfer_blocking(&bus, &cmd, &txn);
    if (rc == J288_OK) {
        rc = j288_reply_to_si(&txn.reply, J288_SIDE_OUTPUT, &si);
    }
    if (rc != J288_OK) {
        fprintf(stderr, "linux-status: servo %ld: %s\n", id, j288_strerror(rc));
        j288_serial_close(&port);
        return 1;
    }
    printf("servo %ld: output %.4f rad, %.4f rad/s, %.3f N*m; %.1f V, case %.0f C, faults 0x%lx\n",
           id, (double)si.out_pos, (double)si.speed, (double)si.torque, (double)si.voltage_v,
           (double)si.case_temp_c, (unsigned long)si.faults);
    j288_serial_close(&port);
    return 0;
}
