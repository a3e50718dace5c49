/* Raw SocketCAN access: one CAN_RAW socket bound to one interface. */
#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/raw.h>

#include "ncpar/can.h"

int ncp_can_open(struct ncp_can_bus *bus, const char *ifname, struct ncp_diag *d)
{
    bus->fd = -1;
    if (strlen(ifname) >= sizeof bus->ifname)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "CAN interface name '%s' too long", ifname);
    memcpy(bus->ifname, ifname, strlen(ifname) + 1);
    int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "no SocketCAN here (socket AF_CAN: %s)", strerror(errno));
    unsigned idx = if_nametoindex(ifname);
    if (idx == 0) {
        close(fd);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "no CAN interface '%s'", ifname);
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        int e = errno;
        close(fd);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot bind to %s: %s", ifname, strerror(e));
    }
    bus->fd = fd;
    return NCP_OK;
}

void ncp_can_close(struct ncp_can_bus *bus)
{
    if (bus->fd >= 0)
        close(bus->fd);
    bus->fd = -1;
}

int ncp_can_filter(struct ncp_can_bus *bus, const uint32_t *ids, size_t n,
                   struct ncp_diag *d)
{
    struct can_filter flt[64];
    if (n > sizeof flt / sizeof flt[0])
        return ncp_diag_set(d, NCP_ERR_LIMIT, 0, 0, "too many CAN filters (%zu)", n);
    for (size_t i = 0; i < n; i++) {
        flt[i].can_id = ids[i] & CAN_SFF_MASK;
        /* Exact standard-frame match: extended frames never pass. */
        flt[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG;
    }
    if (n == 0) {
        flt[0].can_id = 0;
        flt[0].can_mask = 0;
        n = 1;
    }
    if (setsockopt(bus->fd, SOL_CAN_RAW, CAN_RAW_FILTER, flt,
                   (socklen_t)(n * sizeof flt[0])) < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: cannot set CAN filters: %s",
                            bus->ifname, strerror(errno));
    return NCP_OK;
}

/* Our frame <-> the kernel's: 11-bit ids, RTR flag, at most 8 data bytes. */
static void to_socketcan(const struct ncp_can_frame *f, struct can_frame *cf)
{
    memset(cf, 0, sizeof *cf);
    cf->can_id = (f->id & CAN_SFF_MASK) | (f->rtr ? CAN_RTR_FLAG : 0);
    cf->can_dlc = f->len > 8 ? 8 : f->len;
    memcpy(cf->data, f->data, cf->can_dlc);
}

static void from_socketcan(const struct can_frame *cf, struct ncp_can_frame *f)
{
    memset(f, 0, sizeof *f);
    f->id = cf->can_id & CAN_SFF_MASK;
    f->rtr = (cf->can_id & CAN_RTR_FLAG) != 0;
    f->len = cf->can_dlc > 8 ? 8 : cf->can_dlc;
    memcpy(f->data, cf->data, f->len);
}

int ncp_can_send(struct ncp_can_bus *bus, const struct ncp_can_frame *f,
                 struct ncp_diag *d)
{
    struct can_frame cf;
    to_socketcan(f, &cf);
    for (int tries = 0; tries < 100; tries++) {
        ssize_t w = write(bus->fd, &cf, sizeof cf);
        if (w == (ssize_t)sizeof cf)
            return NCP_OK;
        /* A full transmit queue drains within a few frame times. */
        if (w < 0 && errno == ENOBUFS) {
            poll(NULL, 0, 1);
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        break;
    }
    return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: cannot send CAN frame 0x%03X: %s",
                        bus->ifname, (unsigned)f->id, strerror(errno));
}

int ncp_can_recv(struct ncp_can_bus *bus, struct ncp_can_frame *f, int timeout_ms,
                 struct ncp_diag *d)
{
    struct pollfd p = {.fd = bus->fd, .events = POLLIN};
    int r;
    do
        r = poll(&p, 1, timeout_ms < 0 ? 0 : timeout_ms);
    while (r < 0 && errno == EINTR);
    if (r < 0) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: poll: %s", bus->ifname, strerror(errno));
        return -1;
    }
    if (r == 0)
        return 0;
    struct can_frame cf;
    ssize_t n = read(bus->fd, &cf, sizeof cf);
    if (n != (ssize_t)sizeof cf) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s: read: %s", bus->ifname,
                     n < 0 ? strerror(errno) : "short frame");
        return -1;
    }
    from_socketcan(&cf, f);
    return 1;
}

/* One send() with MSG_DONTWAIT: the real-time path never waits for the queue. */
int ncp_can_try_send(struct ncp_can_bus *bus, const struct ncp_can_frame *f)
{
    struct can_frame cf;
    to_socketcan(f, &cf);
    ssize_t w;
    do
        w = send(bus->fd, &cf, sizeof cf, MSG_DONTWAIT);
    while (w < 0 && errno == EINTR);
    if (w == (ssize_t)sizeof cf)
        return 0;
    if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS))
        return 1;
    if (w >= 0)
        errno = EIO;
    return -1;
}

int ncp_can_try_recv(struct ncp_can_bus *bus, struct ncp_can_frame *f)
{
    struct can_frame cf;
    ssize_t n;
    do
        n = recv(bus->fd, &cf, sizeof cf, MSG_DONTWAIT);
    while (n < 0 && errno == EINTR);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
        return 0;
    if (n != (ssize_t)sizeof cf) {
        if (n >= 0)
            errno = EIO;
        return -1;
    }
    from_socketcan(&cf, f);
    return 1;
}
