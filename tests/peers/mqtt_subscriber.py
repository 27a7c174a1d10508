#!/usr/bin/python3
"""The plant's MES, played by an independent MQTT client (Debian's python3-paho-mqtt 1.6),
for the tests of the station's MQTT results (station/daemon/mqtt_publisher.h).

Subscribes to TOPIC with QoS 1 in a persistent session (clean_session False, a fixed client
id), so that the broker keeps what arrives while this client is away; reconnects by itself
when the broker goes and comes back. Prints one JSON line per event, flushed:
  {"event": "connected"}
  {"event": "message", "topic": ..., "retain": bool, "payload": text, "t": unix seconds}
Runs until it is stopped (SIGTERM). Usage: mqtt_subscriber.py --port P --topic 'plant/#'
[--cafile CA.crt] (TLS, the broker's certificate checked against CA.crt)
"""

import argparse
import json
import signal
import sys
import time

import paho.mqtt.client as mqtt


def emit(obj):
    print(json.dumps(obj), flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, required=True)
    p.add_argument("--topic", required=True)
    p.add_argument("--client-id", default="eol-test-mes")
    p.add_argument("--cafile", default="")
    args = p.parse_args()

    client = mqtt.Client(client_id=args.client_id, clean_session=False)
    if args.cafile:
        client.tls_set(ca_certs=args.cafile)

    def on_connect(c, userdata, flags, rc):
        if rc == 0:
            c.subscribe(args.topic, qos=1)
            emit({"event": "connected"})

    def on_subscribe(c, userdata, mid, granted_qos):
        emit({"event": "subscribed"})

    def on_message(c, userdata, msg):
        emit({"event": "message", "topic": msg.topic, "retain": bool(msg.retain),
              "payload": msg.payload.decode("utf-8", "replace"), "t": time.time()})

    client.on_connect = on_connect
    client.on_subscribe = on_subscribe
    client.on_message = on_message
    client.reconnect_delay_set(min_delay=0.1, max_delay=0.5)
    signal.signal(signal.SIGTERM, lambda *a: sys.exit(0))
    client.connect_async(args.host, args.port, keepalive=10)
    client.loop_forever(retry_first_connection=True)


if __name__ == "__main__":
    main()
