/* A libraw1394 stand-in for the tests: a shared library with libraw1394's
 * C interface (the part hw/firewire/raw1394_api.h declares) over a
 * simulated IEEE 1394 bus, and this control interface beside it. The
 * program reaches it only through VMH_LIBRAW1394 (hw/firewire/
 * raw1394_library.h), which a test sets; a test in the same process takes
 * these functions from the same loaded library (dlsym).
 *
 * The bus, as the public drivers describe the PHANTOM Omni on it
 * (docs/sources.md §9.2):
 *   - ports (host adapters), each with remote nodes and the local one (the
 *     highest node number); a bus generation; an isochronous resource
 *     manager that hands out channels 0..63;
 *   - an Omni node answers four-byte reads of its vendor quadlet at
 *     0x1006000c (0x000b9900 unless configured) and serial at 0x10060010,
 *     the bus information block of its configuration ROM (its GUID in
 *     quadlets 3 and 4), one-byte reads and writes of 0x1000 (host->device
 *     channel), 0x1001 (device->host channel: any byte written reads
 *     back), 0x1082 (0x00), 0x1083 (0xc0), 0x1087 (bit 3: stream), and a
 *     four-byte write of 0x20010; anything else is an address error
 *     (EINVAL), a wrong length a type error (EPERM);
 *   - while 0x1087's bit 3 is set and 0x1001 names a channel, it sends a
 *     44-byte state packet on that channel at its rate (1000 a second
 *     unless configured), its counter one up a packet, and takes the
 *     packets the host transmits on the channel 0x1000 names;
 *   - a bus reset (on demand, or at configured bus times): the generation
 *     moves on, every channel allocation is freed, every Omni stops
 *     streaming and forgets its channels (unless configured to keep its
 *     registers), optionally the nodes are renumbered, and every handle on
 *     the port gets a bus-reset event. A transaction from a handle whose
 *     generation is not the bus's fails with EAGAIN, as a real one does.
 *
 * The libraw1394 side behaves as libraw1394 2.1.2 on firewire-core
 * (src/fw-iso.c): a handle's file descriptor is readable while it has
 * events; raw1394_loop_iterate takes one event: a bus reset (the bus-reset
 * handler, by default raw1394_update_generation), one receive interrupt
 * (irq_interval packets to the receive handler, each with its bus cycle)
 * or one transmit interrupt (the transmit handler fills every free slot).
 * The receive buffer holds buf_packets packets; more are dropped. The
 * transmit context sends its oldest filled slot every bus cycle (8000 a
 * second); a cycle with none is an underrun. With no event waiting,
 * raw1394_loop_iterate returns -1 with errno EAGAIN on the virtual clock
 * (a real one would block) and waits up to a second on the wall clock.
 *
 * Time: a virtual clock, advanced only by fwsim_advance_ns (deterministic
 * tests), or the wall clock, on which a thread of the library runs the
 * bus. Every async transaction may be made to fail with EAGAIN now and
 * then. Every transaction is logged (fwsim_log_*; to a file with log=).
 *
 * Configuration: fwsim_configure(text), or VMH_FWSIM in the environment
 * at the first call into the library; items separated by ';':
 *   clock=virtual|wall        (default virtual)
 *   port[=NAME]               a new port; nodes go on the last one (a
 *                             first node without one makes "fwsim0")
 *   omni=GUID[,KEY=VALUE...]  an Omni (GUID: hex). KEYs: rate (packets a
 *                             second), vendor, serial (hex quadlets),
 *                             counts=C1/C2/C3 (encoders at the start),
 *                             speed=S1/S2/S3 (counts a second), pots=P1/P2/P3
 *                             (11-bit codes), docked=0|1, buttons=B (bits 0,
 *                             1: pressed), program=calibrate (docked for
 *                             dock_s seconds from its first stream, then
 *                             every pot swept between its codes sweep_lo and
 *                             sweep_hi, period 1 s), dock_s=S,
 *                             sweep_lo=L1/L2/L3, sweep_hi=H1/H2/H3 (default
 *                             300 and 1700), keep_on_reset=0|1,
 *                             quirk=no-readback (0x1001 reads 0x3f whatever
 *                             was written) or quirk=not-ready (0x1083 reads
 *                             0x40)
 *   node=GUID[,vendor=HEX]    a node that is not an Omni (its vendor
 *                             quadlet read fails unless given)
 *   eagain=N                  every Nth async transaction fails with EAGAIN
 *   eagain_next=K             the next K do
 *   reset_at=T[,T...]         bus resets on the first port at bus times (s)
 *   reset_after_start=T[,T...]  the same, T seconds after an Omni first
 *                             starts streaming
 *   renumber=0|1              renumber the remote nodes at each reset
 *   log=PATH                  append each transaction to PATH, one a line
 *
 * Built only by the tests (tests/hw/firewire/CMakeLists.txt); no part of
 * the program.
 */
#ifndef VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_H_
#define VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_H_

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What a node is doing, for a test to look at. */
struct fwsim_node_info {
  uint64_t guid;
  int port;
  int phy;                  /* node number now (renumbering moves it) */
  int omni;                 /* answers as an Omni */
  int streaming;            /* sending state packets */
  uint8_t reg_tx_channel;   /* 0x1000 */
  uint8_t reg_rx_channel;   /* 0x1001 */
  uint8_t reg_control;      /* 0x1087 */
  uint8_t reg_20010[4];     /* 0x20010, as written (bus order) */
  int wrote_20010;
  uint32_t counter;         /* of the last packet sent */
  uint64_t packets_sent;    /* state packets put on the bus */
  uint64_t packets_received;  /* of those, taken into a host's buffer */
  uint64_t packets_dropped;   /* of those, dropped: the host's buffer full */
  uint64_t commands;        /* command packets the node took */
  uint8_t last_command[16];
  int64_t last_command_ns;
  int32_t encoder_counts[3];  /* the built-in model's, at the last packet */
  int64_t last_packet_ns;
};

/* A transaction as the bus saw it. */
struct fwsim_transaction {
  int64_t t_ns;
  int port;
  int phy;
  uint64_t guid;     /* the node's, 0: none there */
  char op;           /* 'r' or 'w' */
  uint64_t addr;
  uint32_t len;
  uint8_t data[4];   /* written, or read (the first four bytes) */
  int error;         /* 0, or the errno the caller got */
};

/* A device model for an Omni node in place of the built-in one (the
 * emulator behind the bus, in a test). */
struct fwsim_device_ops {
  void* user;
  /* the state packet the node sends at bus time t_ns into out (capacity
   * bytes); returns its length, 0 to send nothing this time */
  unsigned (*state)(void* user, int64_t t_ns, uint8_t* out, unsigned capacity);
  /* a command packet the node took at bus time t_ns */
  void (*command)(void* user, int64_t t_ns, const uint8_t* data, unsigned len);
};

/* Replaces the whole bus (every handle must be closed). 0, or -1 with
 * fwsim_last_error() naming the item. */
int fwsim_configure(const char* text);
const char* fwsim_last_error(void);

int64_t fwsim_now_ns(void);
/* virtual clock: run the bus for ns (ignored on the wall clock) */
void fwsim_advance_ns(int64_t ns);
/* a bus reset on the port, now; -1 for a bad port */
int fwsim_bus_reset(int port);

/* the node with this GUID; -1 when none */
int fwsim_get_node(uint64_t guid, struct fwsim_node_info* out);
int fwsim_set_encoder_speed(uint64_t guid, double s1, double s2, double s3);
int fwsim_set_docked(uint64_t guid, int docked);
/* a model in place of the built-in one (null: the built-in one again) */
int fwsim_attach_device(uint64_t guid, const struct fwsim_device_ops* ops);

/* every Nth async transaction fails with EAGAIN (0: none), and the next K */
void fwsim_eagain(int every_nth, int next_k);
/* transactions that failed with EAGAIN so far */
long fwsim_eagain_count(void);
/* transmit cycles that found no filled slot, over every context */
long fwsim_underruns(void);

long fwsim_log_size(void);
int fwsim_log_entry(long i, struct fwsim_transaction* out);
void fwsim_log_clear(void);

#ifdef __cplusplus
}
#endif

#endif /* VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_H_ */
