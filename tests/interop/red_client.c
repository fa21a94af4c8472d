/* A cable-redundant master for the redundancy interop test (docs/topology.md, "Cable
 * redundancy"): SOEM (v1.4.0, or v2.0.0 with -DSOEM_V2) opened on two ports with
 * ec_init_redundant (v2: ecx_init_redundant with its own ecx_redportt), or for the control run
 * on the first port only, brings the network to OP and exchanges process data
 * every millisecond, counting the cycles whose working counter is not the whole network's.
 * SOEM's own red_test has its ec_init_redundant call commented out, hence this client.
 * A separate program: built against SOEM's libsoem.a by the ctest fixture (build_soem.sh),
 * never linked into ecsim.
 *
 * usage: red_client IF1 IF2|- SECONDS
 * prints: "slaves N", "op wkc E" once every slave is in OP (or "not in OP: ..." and exit 4),
 *         "wkc W at cycle C" whenever the working counter changes, and at the end
 *         "done cycles C lost L" (L: cycles whose working counter was not E).
 * exit: 0 after SECONDS of cycles, 2 on bad arguments, 3 when no slave was found.
 *
 * A cycle's frames may take RECEIVE_TIMEOUT_US to come back, not SOEM's EC_TIMEOUTRET (2 ms),
 * as ecmaster's ring runs get 5 ms (soem_redundancy_test.cpp): the test hosts stall server and
 * client alike for more than 2 ms many times a minute, idle. v2.0.0 keeps to its timeout to the
 * poll (ppoll at 50 us, oshw/linux/nicdrv.c:505-523) and lost those cycles on a whole ring;
 * v1.4.0's recv() blocks a whole jiffy (SO_RCVTIMEO of 1 us) before it looks at its timer, and
 * waited anyway. The wait for the frame SOEM sends again from the second port at a break stays
 * EC_TIMEOUTRET.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef SOEM_V2
#include "soem/soem.h"
static ecx_contextt ctx;
static ecx_redportt redport;
#define SLAVECOUNT (ctx.slavecount)
#define SLAVE(i) (ctx.slavelist[i])
#define GROUP0 (ctx.grouplist[0])
#define INIT(ifname) ecx_init(&ctx, ifname)
#define INIT_REDUNDANT(a, b) ecx_init_redundant(&ctx, &redport, a, b)
#define CONFIG_INIT() ecx_config_init(&ctx)
#define CONFIG_MAP(map) ecx_config_map_group(&ctx, map, 0)
#define STATECHECK(s, st, t) ecx_statecheck(&ctx, s, st, t)
#define WRITESTATE(s) ecx_writestate(&ctx, s)
#define READSTATE() ecx_readstate(&ctx)
#define SEND() ecx_send_processdata(&ctx)
#define RECEIVE() ecx_receive_processdata(&ctx, RECEIVE_TIMEOUT_US)
#define CLOSE() ecx_close(&ctx)
#else
#include "ethercat.h"
#define SLAVECOUNT (ec_slavecount)
#define SLAVE(i) (ec_slave[i])
#define GROUP0 (ec_group[0])
#define INIT(ifname) ec_init(ifname)
#define INIT_REDUNDANT(a, b) ec_init_redundant(a, b)
#define CONFIG_INIT() ec_config_init(FALSE)
#define CONFIG_MAP(map) ec_config_map(map)
#define STATECHECK(s, st, t) ec_statecheck(s, st, t)
#define WRITESTATE(s) ec_writestate(s)
#define READSTATE() ec_readstate()
#define SEND() ec_send_processdata()
#define RECEIVE() ec_receive_processdata(RECEIVE_TIMEOUT_US)
#define CLOSE() ec_close()
#endif

#define RECEIVE_TIMEOUT_US 5000

static char io_map[4096];

static void next_cycle(struct timespec *t)
{
   t->tv_nsec += 1000000;
   if (t->tv_nsec >= 1000000000)
   {
      t->tv_nsec -= 1000000000;
      t->tv_sec += 1;
   }
   clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t, NULL);
}

int main(int argc, char *argv[])
{
   if (argc != 4)
   {
      fprintf(stderr, "usage: %s IF1 IF2|- SECONDS\n", argv[0]);
      return 2;
   }
   const int redundant = strcmp(argv[2], "-") != 0;
   const int seconds = atoi(argv[3]);
   const int opened = redundant ? INIT_REDUNDANT(argv[1], argv[2]) : INIT(argv[1]);
   if (!opened)
   {
      printf("init on %s failed\n", argv[1]);
      return 3;
   }
   if (CONFIG_INIT() <= 0)
   {
      printf("slaves 0\n");
      CLOSE();
      return 3;
   }
   printf("slaves %d\n", SLAVECOUNT);
   CONFIG_MAP(&io_map);
   STATECHECK(0, EC_STATE_SAFE_OP, EC_TIMEOUTSTATE * 4);
   const int expected_wkc = (GROUP0.outputsWKC * 2) + GROUP0.inputsWKC;
   SLAVE(0).state = EC_STATE_OPERATIONAL;
   SEND();
   RECEIVE();
   WRITESTATE(0);
   for (int tries = 200; tries > 0 && SLAVE(0).state != EC_STATE_OPERATIONAL; --tries)
   {
      SEND();
      RECEIVE();
      STATECHECK(0, EC_STATE_OPERATIONAL, 50000);
   }
   if (SLAVE(0).state != EC_STATE_OPERATIONAL)
   {
      READSTATE();
      for (int i = 1; i <= SLAVECOUNT; i++)
      {
         if (SLAVE(i).state != EC_STATE_OPERATIONAL)
         {
            printf("not in OP: slave %d state 0x%02x\n", i, SLAVE(i).state);
         }
      }
      CLOSE();
      return 4;
   }
   printf("op wkc %d\n", expected_wkc);
   fflush(stdout);
   int lost = 0;
   int last_wkc = expected_wkc;
   const int cycles = seconds * 1000;
   struct timespec t;
   clock_gettime(CLOCK_MONOTONIC, &t);
   for (int c = 0; c < cycles; c++)
   {
      SEND();
      const int wkc = RECEIVE();
      if (wkc != expected_wkc) lost++;
      if (wkc != last_wkc)
      {
         printf("wkc %d at cycle %d\n", wkc, c);
         fflush(stdout);
         last_wkc = wkc;
      }
      next_cycle(&t);
   }
   printf("done cycles %d lost %d\n", cycles, lost);
   SLAVE(0).state = EC_STATE_INIT;
   WRITESTATE(0);
   CLOSE();
   return 0;
}
